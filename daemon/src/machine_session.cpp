#include "machine_session.hpp"

#include <chrono>
#include <stdexcept>

#include <boost/asio/io_context.hpp>
#include <fmt/format.h>

#include "lamina/drivers/link_factory.hpp"
#include "lamina/drivers/modbus_endpoint.hpp"

namespace lamina::daemon {
namespace {

std::pair<std::string, int> host_port(const std::string& text, const char* what) {
  auto hp = drivers::parse_host_port(text);
  if (!hp) throw std::invalid_argument(fmt::format("{} '{}': expected HOST:PORT", what, text));
  return *hp;
}

// The cell's PLC, described once for both of its users (the mailbox link and CellIo).
drivers::ModbusEndpoint plc_endpoint(const CellConfig& c) {
  drivers::ModbusEndpoint e;
  std::tie(e.host, e.port) = host_port(c.modbus, "[cell] modbus");
  e.unit_id = c.modbus_unit;
  e.response_timeout_s = c.modbus_timeout_s;
  e.max_reconnects = c.modbus_reconnects;
  return e;
}

nlohmann::json position_json(const std::optional<std::array<double, 5>>& p) {
  if (!p) return nullptr;
  return {{"x_mm", (*p)[0]}, {"y_mm", (*p)[1]}, {"z_mm", (*p)[2]}, {"a_deg", (*p)[3]}, {"c_deg", (*p)[4]}};
}

}  // namespace

MachineSession::MachineSession(const DaemonConfig& config)
    : hold_limit_s_(config.cell.hold_limit_s), jet_restart_s_(config.cell.jet_restart_s) {
  drivers::LinkSettings link = config.link;
  if (drivers::find_link_protocol(link.protocol) && drivers::find_link_protocol(link.protocol)->traits.mailbox)
    link.plc = plc_endpoint(config.cell);  // the mailbox is the cell PLC's
  auto built = drivers::make_link(link);
  if (!built) throw std::invalid_argument("[link] " + built.error());
  link_ = std::move(built->link);
  protocol_ = built->protocol;
  describe_ = built->protocol->traits.mailbox ? fmt::format("Modbus mailbox on {}", config.cell.modbus)
                                              : std::move(built->description);
  if (config.cell.enabled) {
    drivers::CellIoSettings cs;
    cs.plc = plc_endpoint(config.cell);
    cs.heartbeat_period_s = config.cell.heartbeat_period_s;
    cs.idle_poll_period_s = config.cell.idle_poll_s;
    cs.pump_ready_timeout_s = config.cell.pump_ready_timeout_s;
    cs.pressure_setpoint_01mpa = static_cast<std::uint16_t>(config.cell.pressure_setpoint_mpa * 10 + 0.5);
    cs.abrasive_g_per_min = static_cast<std::uint16_t>(config.cell.abrasive_g_per_min + 0.5);
    cell_ = std::make_unique<drivers::CellIo>(cs);
    describe_ += fmt::format(", PLC {}", config.cell.modbus);
  }
}

drivers::CutJobSettings MachineSession::cut_settings() const {
  drivers::CutJobSettings s = drivers::cut_settings_for(*protocol_);
  s.hold_limit_s = hold_limit_s_;
  s.jet_restart_s = jet_restart_s_;
  return s;
}

// The PLC's values only while the PLC is reachable: unreachable (or never read), they read as
// null — unknown — instead of the last ones (they showed jet on, 380 MPa with the PLC gone).
// read_age_s says how old they are: between cuts nothing polls the PLC.
static nlohmann::json cell_json(const drivers::CellStatus& c) {
  const std::optional<double> age_s =
      c.read_at ? std::optional(std::chrono::duration<double>(std::chrono::steady_clock::now() - *c.read_at).count())
                : std::nullopt;
  const bool fresh = c.connected && age_s;
  const auto value = [&](auto v) { return fresh ? nlohmann::json(v) : nlohmann::json(nullptr); };
  return {{"connected", c.connected},
          {"read_age_s", age_s ? nlohmann::json(*age_s) : nlohmann::json(nullptr)},
          {"estop_ok", value(c.estop_ok)},
          {"door_closed", value(c.door_closed)},
          {"pump_ready", value(c.pump_ready)},
          {"jet_is_on", value(c.jet_is_on)},
          {"pressure_mpa", value(c.pressure_mpa)},
          {"abrasive_g_per_min", value(c.abrasive_g_per_min)},
          {"alarm_latched", value(c.alarm_latched)},
          {"alarm_code", value(c.alarm_code)}};
}

nlohmann::json MachineSession::status() const {
  const drivers::LinkProgress p = link_->progress();
  nlohmann::json j{{"link", describe_}, {"state", "unknown"}};
  if (p.last_status) {
    const drivers::ControllerStatus& s = *p.last_status;
    j["state"] = drivers::to_string(s.state);
    j["state_text"] = s.state_text;
    j["position"] = position_json(s.machine_position);
    j["feed_mm_per_s"] = s.feed_mm_per_s ? nlohmann::json(*s.feed_mm_per_s) : nlohmann::json(nullptr);
    j["line"] = s.line_number ? nlohmann::json(*s.line_number) : nlohmann::json(nullptr);
    j["planner_blocks_free"] = s.planner_blocks_free ? nlohmann::json(*s.planner_blocks_free) : nlohmann::json(nullptr);
  }
  j["lines_sent"] = p.lines_sent;
  j["lines_accepted"] = p.lines_accepted;
  if (cell_) {
    j["cell"] = cell_json(cell_->status());
    if (!p.last_status && !j["cell"]["estop_ok"].is_null()) j["state"] = drivers::to_string(cell_->status().cnc_state);
    if (const auto f = cell_->fault()) j["cell"]["fault"] = f->message;
  }
  return j;
}

std::string MachineSession::describe() const { return describe_; }

}  // namespace lamina::daemon
