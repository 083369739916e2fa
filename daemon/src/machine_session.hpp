#pragma once
// The cell as the daemon holds it for its lifetime: one link to the CNC and one CellIo for the
// PLC, built from [link] and [cell]. Both keep their connections between jobs. Only the cutting
// thread streams; status and real-time requests may come from any thread.
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "lamina/daemon/daemon_config.hpp"
#include "lamina/drivers/cell_io.hpp"
#include "lamina/drivers/cut_job.hpp"
#include "lamina/drivers/machine_link.hpp"

namespace lamina::daemon {

class MachineSession {
 public:
  explicit MachineSession(const DaemonConfig& config);  // throws std::invalid_argument on a bad address
  drivers::MachineLink& link() { return *link_; }
  drivers::CellIo* cell() { return cell_.get(); }
  drivers::CutJobSettings cut_settings() const;
  // state, position, feed, line, Bf, the cell's pressure and interlocks — machine.status.
  nlohmann::json status() const;
  std::string describe() const;  // "grbl on /dev/ttyUSB0, PLC 10.0.0.5:502"

 private:
  const drivers::LinkProtocol* protocol_ = nullptr;
  double hold_limit_s_ = 600, jet_restart_s_ = 1.0;  // [cell]: what a feed hold does to the jet
  std::string describe_;
  std::unique_ptr<drivers::MachineLink> link_;
  std::unique_ptr<drivers::CellIo> cell_;
};

}  // namespace lamina::daemon
