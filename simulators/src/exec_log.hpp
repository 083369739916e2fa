#pragma once
// The execution log (--log FILE): JSON lines, one record per executed block plus event
// records, flushed per record so a test (or a post-mortem) reads what happened up to a crash.
//   {"seq":12,"line":"G1X10F600","start":[x,y,z,a,c],"end":[…],"jet":true,"t_start":1.25,"t_end":1.5}
//   with a head (the machine file's head_* keys) also "tip":[x,y,z] and "axis":[…] at the block's end
//   {"event":"starvation","t":2.0,"after_seq":40}
//   {"event":"alarm","t":3.1,"code":2,"seq":41}
//   {"event":"<name>", "t":…, …}   (connects, unplugs, faults: see docs/simulator.md)
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "jet_head.hpp"
#include "machine.hpp"

namespace lamina::sim {

nlohmann::json to_json_record(const MachineEvent& event, const std::optional<HeadGeometry>& head = std::nullopt);

class ExecLog {
 public:
  // Empty path: a log that writes nothing. Throws std::runtime_error if the file cannot open.
  explicit ExecLog(const std::string& path, std::optional<HeadGeometry> head = std::nullopt);
  ~ExecLog();
  ExecLog(const ExecLog&) = delete;
  ExecLog& operator=(const ExecLog&) = delete;

  void write(const MachineEvent& event);
  void write_event(std::string_view name, double t_s, nlohmann::json fields = nlohmann::json::object());

 private:
  void write_line(const nlohmann::json& record);
  std::FILE* file_ = nullptr;
  std::optional<HeadGeometry> head_;
};

}  // namespace lamina::sim
