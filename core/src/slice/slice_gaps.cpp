// The gap rule for open meshes: a chain's end is joined to the nearest free chain start (its own
// included) when the gap is at most gap_mm, nearest pairs first. The joining vector has no facet
// (facet -1), so later stages can see it is invented, and every use is reported.
#include "slice/slice_internal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <tuple>

namespace lamina::slice_detail {

std::vector<Loop> close_gaps(std::vector<OpenChain>& chains, double gap_mm,
                             std::vector<std::string>& warnings) {
  const std::size_t n = chains.size();
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;  // (gap, from end of i, to start of j)
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      const double d = (chains[i].points.back() - chains[j].points.front()).norm();
      if (d <= gap_mm) pairs.emplace_back(d, i, j);
    }
  std::sort(pairs.begin(), pairs.end());
  std::vector<std::ptrdiff_t> next(n, -1);
  std::vector<char> has_prev(n, 0);
  double widest = 0.0;
  for (const auto& [d, i, j] : pairs) {
    if (next[i] >= 0 || has_prev[j]) continue;
    next[i] = static_cast<std::ptrdiff_t>(j);
    has_prev[j] = 1;
  }

  std::vector<Loop> loops;
  std::vector<char> done(n, 0);
  std::size_t joined = 0;
  for (std::size_t start = 0; start < n; ++start) {
    if (done[start]) continue;
    // Follow the links; only a cycle becomes a loop.
    std::size_t cur = start;
    std::vector<std::size_t> cycle;
    bool is_cycle = false;
    std::vector<char> seen(n, 0);
    while (next[cur] >= 0 && !seen[cur] && !done[cur]) {
      seen[cur] = 1;
      cycle.push_back(cur);
      cur = static_cast<std::size_t>(next[cur]);
      if (cur == start) {
        is_cycle = true;
        break;
      }
    }
    if (!is_cycle) continue;
    Loop loop;
    loop.gap_closed = true;
    for (const std::size_t c : cycle) {
      done[c] = 1;
      const OpenChain& ch = chains[c];
      // Its vectors, then the gap vector from its last point to the next chain's first point.
      for (std::size_t k = 0; k + 1 < ch.points.size(); ++k) {
        loop.points.push_back(ch.points[k]);
        loop.facets.push_back(ch.facets[k]);
      }
      const auto& to = chains[static_cast<std::size_t>(next[c])].points.front();
      widest = std::max(widest, (ch.points.back() - to).norm());
      if (ch.points.back() != to) {
        loop.points.push_back(ch.points.back());
        loop.facets.push_back(-1);
      }
    }
    joined += cycle.size();
    if (loop.points.size() >= 3) loops.push_back(std::move(loop));
  }
  if (joined > 0)
    warnings.push_back(fmt::format("{} open chain(s) closed into {} loop(s) by the gap rule (widest gap {:.4g} mm)",
                                   joined, loops.size(), widest));
  std::vector<OpenChain> left;
  for (std::size_t i = 0; i < n; ++i)
    if (!done[i]) left.push_back(std::move(chains[i]));
  if (!left.empty())
    warnings.push_back(fmt::format("{} open chain(s) could not be closed within {:.4g} mm and were left out",
                                   left.size(), gap_mm));
  chains = std::move(left);
  return loops;
}

}  // namespace lamina::slice_detail
