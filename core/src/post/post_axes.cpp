// Machine axes of a toolpath: continuous inverse kinematics, then (limited C) the turn shift of
// every contour and the rewinds in the rapids between contours.
#include "post/post_internal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

namespace lamina::post_detail {

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;
constexpr double range_slack_rad = 1e-9;
constexpr double same_height_mm = 1e-6;

const char* kind_word(MoveKind kind) {
  switch (kind) {
    case MoveKind::rapid: return "rapid";
    case MoveKind::pierce: return "pierce";
    case MoveKind::lead_in: return "lead-in";
    case MoveKind::cut: return "cut";
    case MoveKind::lead_out: return "lead-out";
  }
  return "move";
}

bool in_c_range(double c, const HeadKinematics& head) {
  return c >= head.c_min_rad - range_slack_rad && c <= head.c_max_rad + range_slack_rad;
}

// The c + 2πk in range nearest to prev_c, if any.
std::optional<double> in_range_turn(double c, double prev_c, const HeadKinematics& head) {
  const double k_lo = std::ceil((head.c_min_rad - c) / two_pi - 1e-12);
  const double k_hi = std::floor((head.c_max_rad - c) / two_pi + 1e-12);
  if (k_lo > k_hi) return std::nullopt;
  const double k = std::clamp(std::round((prev_c - c) / two_pi), k_lo, k_hi);
  return c + two_pi * k;
}

// Which contour each move belongs to (-1: none); contours must be disjoint runs of moves.
std::expected<std::vector<int>, Error> contour_of_moves(const SheetToolpath& toolpath) {
  const std::vector<ToolMove>& moves = toolpath.moves;
  std::vector<int> contour_of(moves.size(), -1);
  for (std::size_t ci = 0; ci < toolpath.contours.size(); ++ci) {
    const ToolContour& c = toolpath.contours[ci];
    if (c.first_move >= c.end_move || c.end_move > moves.size())
      return std::unexpected(Error{ErrorCode::invalid_argument,
                                   fmt::format("contour {}: moves [{}, {}) not within the {} moves", ci,
                                               c.first_move, c.end_move, moves.size())});
    for (std::size_t i = c.first_move; i < c.end_move; ++i) {
      if (contour_of[i] >= 0)
        return std::unexpected(Error{ErrorCode::invalid_argument,
                                     fmt::format("contours {} and {} share move {}", contour_of[i], ci, i)});
      contour_of[i] = static_cast<int>(ci);
    }
  }
  return contour_of;
}

// Step 1: continuous inverse over the whole program.
std::expected<std::vector<AxisPose>, Error> continuous_inverse(const std::vector<ToolMove>& moves,
                                                               const std::vector<int>& contour_of,
                                                               const HeadKinematics& head) {
  std::vector<AxisPose> poses;
  poses.reserve(moves.size());
  double prev_c = 0.0;
  for (std::size_t i = 0; i < moves.size(); ++i) {
    auto pose = inverse_kinematics(moves[i].tip_mm, moves[i].axis, prev_c, head);
    if (!pose) {
      const std::string where = contour_of[i] >= 0
                                    ? fmt::format("contour {} ({} move {})", contour_of[i], kind_word(moves[i].kind), i)
                                    : fmt::format("{} move {}", kind_word(moves[i].kind), i);
      return std::unexpected(Error{pose.error().code, where + ": " + pose.error().message});
    }
    prev_c = pose->c_rad;
    poses.push_back(*pose);
  }
  return poses;
}

// The moves [first, end) solved continuously from `prev`; none when one has no solution.
std::optional<std::vector<AxisPose>> solve_run(const std::vector<ToolMove>& moves, std::size_t first, std::size_t end,
                                               double prev, const HeadKinematics& head) {
  std::vector<AxisPose> run;
  for (std::size_t m = first; m < end; ++m) {
    auto pose = inverse_kinematics(moves[m].tip_mm, moves[m].axis, prev, head);
    if (!pose) return std::nullopt;
    prev = pose->c_rad;
    run.push_back(*pose);
  }
  return run;
}

// One contour's choice: which branch (index into the options) and which 2πk.
struct TurnChoice {
  std::size_t option = 0;
  double k = 0.0;
};

// The option and turn that keep the whole contour in range with its first C nearest `target`;
// none when no option fits. `lo0`/`hi0`: the first option's C span, for the error.
std::optional<TurnChoice> best_turn(const std::vector<std::vector<AxisPose>>& options, double target,
                                    const HeadKinematics& head, double& lo0, double& hi0) {
  std::optional<TurnChoice> best;
  double best_cost = 0.0;
  for (std::size_t o = 0; o < options.size(); ++o) {
    double lo = options[o].front().c_rad, hi = lo;
    for (const AxisPose& p : options[o]) {
      lo = std::min(lo, p.c_rad);
      hi = std::max(hi, p.c_rad);
    }
    if (o == 0) lo0 = lo, hi0 = hi;
    const double k_lo = std::ceil((head.c_min_rad - lo) / two_pi - 1e-12);
    const double k_hi = std::floor((head.c_max_rad - hi) / two_pi + 1e-12);
    if (k_lo > k_hi) continue;
    const double first = options[o].front().c_rad;
    const double k = std::clamp(std::round((target - first) / two_pi), k_lo, k_hi);
    const double cost = std::abs(first + two_pi * k - target);
    if (!best || cost < best_cost - 1e-12) {
      best = TurnChoice{o, k};
      best_cost = cost;
    }
  }
  return best;
}

// Step 2, limited C: per contour, one of the two branches of the inverse — (A, C) as it came, or
// (−A, C + π) all along — and one 2πk shift, chosen so the whole contour is in range and its
// first C is nearest to where the head was. Writes the branch into `poses`; returns the shifts.
std::expected<std::vector<double>, Error> contour_shifts(const SheetToolpath& toolpath, const HeadKinematics& head,
                                                         std::vector<AxisPose>& poses) {
  const std::vector<ToolMove>& moves = toolpath.moves;
  std::vector<double> shift(toolpath.contours.size(), 0.0);
  std::vector<std::size_t> order(toolpath.contours.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return toolpath.contours[a].first_move < toolpath.contours[b].first_move;
  });
  std::optional<double> last_c;  // shifted C at the end of the previous contour
  for (std::size_t ci : order) {
    const ToolContour& c = toolpath.contours[ci];
    std::vector<std::vector<AxisPose>> options;
    options.emplace_back(poses.begin() + static_cast<std::ptrdiff_t>(c.first_move),
                         poses.begin() + static_cast<std::ptrdiff_t>(c.end_move));
    if (auto flipped = solve_run(moves, c.first_move, c.end_move, poses[c.first_move].c_rad + std::numbers::pi, head);
        flipped && std::abs(flipped->front().a_rad - options[0].front().a_rad) > 1e-12)
      options.push_back(std::move(*flipped));
    double lo0 = 0.0, hi0 = 0.0;
    const auto best = best_turn(options, last_c.value_or(0.0), head, lo0, hi0);
    if (!best)
      return std::unexpected(Error{
          ErrorCode::invalid_argument,
          fmt::format("contour {}: C travels {:.3f} deg ({:.3f} to {:.3f}), which does not fit the C range "
                      "[{:.3f}, {:.3f}] deg at any turn of either head solution",
                      ci, (hi0 - lo0) * deg_per_rad, lo0 * deg_per_rad, hi0 * deg_per_rad,
                      head.c_min_rad * deg_per_rad, head.c_max_rad * deg_per_rad)});
    std::copy(options[best->option].begin(), options[best->option].end(),
              poses.begin() + static_cast<std::ptrdiff_t>(c.first_move));
    shift[ci] = two_pi * best->k;
    last_c = poses[c.end_move - 1].c_rad + shift[ci];
  }
  return shift;
}

// Step 3's shift of every move: contour moves take their contour's. A contour starts with the
// rapid over its pierce point at safe height, so the rewind is that rapid. Moves outside every
// contour (the park rapids; or a toolpath whose contours start at the pierce) take the previous
// contour's shift until the head is up at travel height, then the next one's (the rewind is the
// first move that starts at the run's highest point).
std::vector<double> move_shifts(const std::vector<ToolMove>& moves, const std::vector<int>& contour_of,
                                const std::vector<double>& shift) {
  std::vector<double> applied(moves.size(), 0.0);
  for (std::size_t m = 0; m < moves.size(); ++m)
    if (contour_of[m] >= 0) applied[m] = shift[static_cast<std::size_t>(contour_of[m])];
  auto start_z = [&](std::size_t m) { return m > 0 ? moves[m - 1].tip_mm.z() : moves[m].tip_mm.z(); };
  for (std::size_t i = 0; i < moves.size();) {
    if (contour_of[i] >= 0) {
      ++i;
      continue;
    }
    const std::size_t begin = i;
    while (i < moves.size() && contour_of[i] < 0) ++i;
    const std::size_t end = i;  // [begin, end) rapids
    // Shift before the rewind and after it; a run at the program's start or end has one side only.
    const bool has_before = begin > 0, has_after = end < moves.size();
    const double before = has_before ? shift[static_cast<std::size_t>(contour_of[begin - 1])] : 0.0;
    const double after = has_after ? shift[static_cast<std::size_t>(contour_of[end])] : 0.0;
    double top = start_z(begin);
    for (std::size_t m = begin; m < end; ++m) top = std::max(top, moves[m].tip_mm.z());
    std::size_t rewind = begin;
    while (rewind < end && start_z(rewind) < top - same_height_mm) ++rewind;
    if (rewind == end) rewind = end - 1;
    for (std::size_t m = begin; m < end; ++m) applied[m] = has_before && (m < rewind || !has_after) ? before : after;
  }
  return applied;
}

// Step 3: every move's C shifted into range; a move outside the contours that its shift leaves
// out of range takes the turn in range nearest the move before.
std::expected<void, Error> apply_shifts(const std::vector<ToolMove>& moves, const std::vector<int>& contour_of,
                                        const std::vector<double>& applied, const HeadKinematics& head,
                                        std::vector<AxisPose>& poses) {
  for (std::size_t m = 0; m < moves.size(); ++m) {
    const double c = poses[m].c_rad + applied[m];
    if (in_c_range(c, head)) {
      poses[m].c_rad = c;
      continue;
    }
    if (contour_of[m] >= 0)  // cannot happen: the contour's shift was chosen to fit
      return std::unexpected(Error{ErrorCode::invalid_argument, fmt::format("contour {}: C out of range", contour_of[m])});
    const double prev = m > 0 ? poses[m - 1].c_rad : c;
    const auto turned = in_range_turn(poses[m].c_rad, prev, head);
    if (!turned)
      return std::unexpected(Error{ErrorCode::invalid_argument,
                                   fmt::format("{} move {}: C {:.3f} deg is outside the C range [{:.3f}, {:.3f}] deg "
                                               "at every turn",
                                               kind_word(moves[m].kind), m, poses[m].c_rad * deg_per_rad,
                                               head.c_min_rad * deg_per_rad, head.c_max_rad * deg_per_rad)});
    poses[m].c_rad = *turned;
  }
  return {};
}

// Step 4: a vertical head's C is free (every C gives the same axis), so runs of vertical moves
// take it from their tilted neighbours: the first from the move before, the rest from the move
// after. A pivot head then never turns C while A leaves or reaches 0 — a C sweep with A tilting
// swings the tip on a circle of pivot·sin A (5 mm at 2° on a 150 mm pivot) — and C turns in the
// run's vertical moves (the rapid down to the pierce), where it moves nothing.
void align_vertical_c(std::vector<AxisPose>& poses) {
  const std::size_t n = poses.size();
  for (std::size_t b = 0; b < n;) {
    if (poses[b].a_rad != 0.0) {
      ++b;
      continue;
    }
    std::size_t e = b;
    while (e < n && poses[e].a_rad == 0.0) ++e;
    const bool has_before = b > 0, has_after = e < n;
    if (has_after)
      for (std::size_t m = has_before ? b + 1 : b; m < e; ++m) poses[m].c_rad = poses[e].c_rad;
    if (has_before) poses[b].c_rad = poses[b - 1].c_rad;
    b = e;
  }
}

}  // namespace

std::expected<std::vector<AxisPose>, Error> plan_machine_axes(const SheetToolpath& toolpath,
                                                             const HeadKinematics& head) {
  auto contour_of = contour_of_moves(toolpath);
  if (!contour_of) return std::unexpected(contour_of.error());
  auto poses = continuous_inverse(toolpath.moves, *contour_of, head);
  if (!poses) return poses;
  const bool limited = std::isfinite(head.c_min_rad) || std::isfinite(head.c_max_rad);
  if (limited && !toolpath.moves.empty()) {
    auto shift = contour_shifts(toolpath, head, *poses);
    if (!shift) return std::unexpected(shift.error());
    const std::vector<double> applied = move_shifts(toolpath.moves, *contour_of, *shift);
    if (auto ok = apply_shifts(toolpath.moves, *contour_of, applied, head, *poses); !ok) return std::unexpected(ok.error());
  }
  align_vertical_c(*poses);
  return poses;
}

}  // namespace lamina::post_detail
