#include "campaign_checks.hpp"

#include <algorithm>
#include <cctype>
#include <map>
#include <optional>

#include <fmt/format.h>

namespace lamina::campaign {
namespace {

// Block boundaries: a jet or state change stamped at a block's first or last instant belongs to
// its neighbour (simulated seconds; a block at 1800 mm/min moves 0.3 µm in this time).
constexpr double kEdgeS = 1e-6;

bool moving_state(const std::string& s) { return s == "run" || s == "hold_pending"; }
bool standing_state(const std::string& s) { return s == "idle" || s == "hold" || s == "alarm"; }

bool is_marker(const std::string& line) { return line.rfind("(CONTOUR ", 0) == 0; }

// The words of a program line outside its comments, upper case, no spaces.
std::string words_of(const std::string& line) {
  std::string out;
  bool comment = false;
  for (char c : line) {
    if (comment) {
      comment = c != ')';
    } else if (c == '(') {
      comment = true;
    } else if (c == ';') {
      break;
    } else if (!std::isspace(static_cast<unsigned char>(c))) {
      out += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    }
  }
  return out;
}

std::optional<int> m_code(const std::string& words) {
  const auto at = words.find('M');
  if (at == std::string::npos) return std::nullopt;
  std::size_t end = at + 1;
  while (end < words.size() && std::isdigit(static_cast<unsigned char>(words[end]))) ++end;
  if (end == at + 1) return std::nullopt;
  return std::stoi(words.substr(at + 1, end - at - 1));
}

// Which program lines cut: a move (an axis word, not a dwell) while the jet M-code is on.
std::vector<bool> cutting_lines(const std::vector<std::string>& program) {
  std::vector<bool> cuts(program.size(), false);
  bool jet = false;
  for (std::size_t i = 0; i < program.size(); ++i) {
    const std::string w = words_of(program[i]);
    if (const auto m = m_code(w)) {
      if (*m == 3 || *m == 4) jet = true;
      if (*m == 5 || *m == 2 || *m == 30) jet = false;
    }
    const bool dwell = w.find("G4") != std::string::npos && w.find_first_of("XYZAC") == std::string::npos;
    cuts[i] = jet && !dwell && w.find_first_of("XYZAC") != std::string::npos;
  }
  return cuts;
}

// Piecewise-constant timelines from the change lists.
class Timeline {
 public:
  explicit Timeline(const MachineLog& log) : log_(log) {}
  // Whether, somewhere strictly inside (a, b), the machine moved with (wet) or without (dry) water.
  bool any_inside(double a, double b, bool wet) const {
    std::vector<double> cuts{a, b};
    for (const auto& c : log_.jet)
      if (c.t_s > a && c.t_s < b) cuts.push_back(c.t_s);
    for (const auto& c : log_.states)
      if (c.t_s > a && c.t_s < b) cuts.push_back(c.t_s);
    std::sort(cuts.begin(), cuts.end());
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
      if (cuts[i + 1] - cuts[i] <= 2 * kEdgeS) continue;
      const double mid = 0.5 * (cuts[i] + cuts[i + 1]);
      if (moving_state(state_at(mid)) && flowing_at(mid) == wet) return true;
    }
    return false;
  }
  bool flowing_at(double t) const {
    bool on = false;
    for (const auto& c : log_.jet) {
      if (c.t_s > t) break;
      on = c.flowing;
    }
    return on;
  }
  std::string state_at(double t) const {
    std::string s = "idle";
    for (const auto& c : log_.states) {
      if (c.t_s > t) break;
      s = c.state;
    }
    return s;
  }

 private:
  const MachineLog& log_;
};

struct Ran {
  std::size_t line;  // program index
  std::size_t pass;
  bool whole;    // completed, and the water flowed whenever it moved
  bool touched;  // the water flowed while it moved, at some point
};

// Program lines the log's blocks were, pass by pass: the first pass starts at the program's
// first line, each resume at a contour marker out of sequence. Lines of neither (a resume's
// set-up) are the daemon's own: cutting one is a violation.
std::vector<Ran> map_blocks(const std::vector<std::string>& program, const MachineLog& log,
                            std::vector<std::string>& violations, std::size_t& passes) {
  std::map<std::string, std::size_t> markers;
  for (std::size_t i = 0; i < program.size(); ++i)
    if (is_marker(program[i])) markers.emplace(program[i], i);
  const Timeline timeline(log);
  std::vector<Ran> out;
  std::optional<std::size_t> cursor;  // the program line expected next
  passes = 0;
  for (const Block& b : log.blocks) {
    const bool touched = b.moved && timeline.any_inside(b.t_start_s, b.t_end_s, true);
    std::optional<std::size_t> index;
    if (cursor && *cursor < program.size() && b.line == program[*cursor]) {
      index = *cursor;
    } else if (auto m = markers.find(b.line); m != markers.end()) {
      index = m->second;
      ++passes;
    } else if (passes == 0 && !program.empty() && b.line == program[0]) {
      index = 0;
      ++passes;
    }
    if (!index) {
      cursor.reset();  // out of the program until the next pass begins
      if (touched)
        violations.push_back(fmt::format("'{}' at t={:.3f} s is not a program line in sequence, and it cut", b.line,
                                         b.t_start_s));
      continue;
    }
    cursor = *index + 1;
    const bool whole = b.completed && !(b.moved && timeline.any_inside(b.t_start_s, b.t_end_s, false));
    out.push_back({*index, passes - 1, whole, touched});
  }
  return out;
}

}  // namespace

MachineLog parse_machine_log(const std::vector<nlohmann::json>& records) {
  MachineLog log;
  for (const auto& r : records) {
    if (r.contains("event")) {
      const std::string e = r["event"];
      if (e == "jet") log.jet.push_back({r.value("t", 0.0), r.value("flowing", false), {}});
      if (e == "state") log.states.push_back({r.value("t", 0.0), false, r.value("state", std::string())});
      if (e == "start") log.initial_scale = r.value("time_scale", 1.0);
      if (e == "time_scale") log.scales.push_back({r.value("t", 0.0), r.value("to", 1.0)});
      continue;
    }
    if (!r.contains("seq")) continue;
    Block b;
    b.line = r.value("line", std::string());
    b.completed = r.value("completed", true);
    b.jet_commanded = r.value("jet", false);
    b.moved = r.contains("start") && r.contains("end") && r["start"] != r["end"];
    b.t_start_s = r.value("t_start", 0.0);
    b.t_end_s = r.value("t_end", 0.0);
    log.blocks.push_back(std::move(b));
  }
  const auto by_time = [](const Change& a, const Change& b) { return a.t_s < b.t_s; };
  std::stable_sort(log.jet.begin(), log.jet.end(), by_time);
  std::stable_sort(log.states.begin(), log.states.end(), by_time);
  return log;
}

ContourCheck check_contours_cut_once(const std::vector<std::string>& program, const MachineLog& log,
                                     bool sheet_complete) {
  ContourCheck out;
  const std::vector<bool> cuts = cutting_lines(program);
  const std::vector<Ran> ran = map_blocks(program, log, out.violations, out.passes);
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i < program.size(); ++i)
    if (is_marker(program[i])) starts.push_back(i);
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const std::size_t begin = starts[k], end = k + 1 < starts.size() ? starts[k + 1] : program.size();
    const auto cutting = static_cast<std::size_t>(std::count(cuts.begin() + begin, cuts.begin() + end, true));
    if (cutting == 0) continue;
    ++out.contours;
    // Per pass, the cutting lines that ran whole; the first pass that ran them all finished it.
    std::map<std::size_t, std::vector<bool>> whole_in_pass;
    std::map<std::size_t, bool> touched_in_pass;
    for (const Ran& r : ran) {
      if (r.line < begin || r.line >= end || !cuts[r.line]) continue;
      auto& lines = whole_in_pass.try_emplace(r.pass, std::vector<bool>(end - begin, false)).first->second;
      if (r.whole) lines[r.line - begin] = true;
      touched_in_pass[r.pass] = touched_in_pass[r.pass] || r.touched;
    }
    std::optional<std::size_t> finished_in;
    for (const auto& [pass, lines] : whole_in_pass) {
      std::size_t whole = 0;
      for (std::size_t i = 0; i < lines.size(); ++i) whole += cuts[begin + i] && lines[i];
      if (whole == cutting) {
        finished_in = pass;
        break;
      }
    }
    const std::string name = program[begin];
    if (finished_in) {
      ++out.finished;
      for (const auto& [pass, touched] : touched_in_pass)
        if (pass > *finished_in && touched)
          out.violations.push_back(fmt::format("{} (line {}) was cut again in pass {} after it was finished in pass {}",
                                               name, begin + 1, pass + 1, *finished_in + 1));
      if (std::count_if(touched_in_pass.begin(), touched_in_pass.end(),
                        [&](const auto& p) { return p.first < *finished_in && p.second; }) > 0)
        ++out.cut_again;
    } else if (sheet_complete) {
      std::size_t first_missing = begin;
      for (std::size_t i = begin; i < end; ++i)
        if (cuts[i]) {
          const bool any_whole = std::any_of(ran.begin(), ran.end(), [&](const Ran& r) { return r.line == i && r.whole; });
          if (!any_whole) {
            first_missing = i;
            break;
          }
        }
      out.violations.push_back(fmt::format("{} (line {}) was never cut whole in one pass: line {} never ran with the "
                                           "water on all along",
                                           name, begin + 1, first_missing + 1));
    }
  }
  return out;
}

double MachineLog::wall_between(double a_s, double b_s) const {
  double wall = 0, t = a_s, scale = initial_scale;
  for (const ScaleChange& c : scales) {
    if (c.t_s <= t) {
      scale = c.scale;
      continue;
    }
    if (c.t_s >= b_s) break;
    wall += (c.t_s - t) / scale;
    t = c.t_s;
    scale = c.scale;
  }
  return wall + (b_s - t) / scale;
}

JetCheck check_jet_off_at_standstill(const MachineLog& log, double limit_wall_s, double restart_wall_s) {
  JetCheck out;
  struct Edge {
    double t;
    bool is_jet;
    bool flowing;
    std::string state;
  };
  std::vector<Edge> edges;
  for (const auto& c : log.jet) edges.push_back({c.t_s, true, c.flowing, {}});
  for (const auto& c : log.states) edges.push_back({c.t_s, false, false, c.state});
  std::stable_sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) { return a.t < b.t; });
  double end_s = 0;
  for (const auto& b : log.blocks) end_s = std::max(end_s, b.t_end_s);
  if (!edges.empty()) end_s = std::max(end_s, edges.back().t);

  bool flowing = false;
  std::string state = "idle";
  struct Episode {
    double since;
    std::string standing_in;
    bool opened_standing;  // the jet came on at a standstill (a restart), not left on by a stop
  };
  std::optional<Episode> open;
  const auto close = [&](double t, bool motion_follows) {
    if (!open) return;
    const double wall_s = log.wall_between(open->since, t);
    const bool restart = open->opened_standing && motion_follows;
    if (restart) {
      ++out.restarts_in_kerf;
      out.worst_restart_wall_s = std::max(out.worst_restart_wall_s, wall_s);
    } else {
      ++out.standstills_with_jet;
      out.worst_wall_s = std::max(out.worst_wall_s, wall_s);
    }
    if (wall_s > (restart ? restart_wall_s : limit_wall_s))
      out.violations.push_back(fmt::format("the jet flowed {:.0f} ms (wall) on a machine standing in {} from t={:.3f} s{}",
                                           wall_s * 1000, open->standing_in, open->since,
                                           restart ? " before it moved on" : ""));
    open.reset();
  };
  bool was_flowing = false;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const Edge& e = edges[i];
    if (e.is_jet) flowing = e.flowing;
    else state = e.state;
    // Changes stamped at one instant settle before they are judged.
    if (i + 1 < edges.size() && edges[i + 1].t - e.t <= kEdgeS) continue;
    const bool bad = flowing && standing_state(state);
    if (bad && !open) open = Episode{e.t, state, !was_flowing};
    if (!bad) close(e.t, flowing && moving_state(state));
    was_flowing = flowing;
  }
  close(end_s, false);
  return out;
}

}  // namespace lamina::campaign
