#include "plan_report.hpp"

#include <fmt/format.h>

#include <optional>
#include <string>

namespace lamina::cli {
namespace {

std::string fixed_or_dash(const std::optional<double>& v, int decimals) {
  return v ? fmt::format("{:.{}f}", *v, decimals) : std::string("-");
}

// Long tables show their first 20 and last 5 rows unless --all-rows; the line between says how
// many are left out. True when row i is shown (the note printed in its place at row 20).
bool row_shown(std::FILE* out, std::size_t i, std::size_t n, bool all_rows) {
  const bool elide = !all_rows && n > 40;
  if (elide && i == 20) fmt::print(out, "{:>5}   ({} more layers: --all-rows or report.json)\n", "...", n - 25);
  return !(elide && i >= 20 && i < n - 5);
}

std::string freed_of(std::int64_t freed, std::int64_t parts) {
  return freed == parts ? fmt::format("{}", parts) : fmt::format("{}/{}", freed, parts);
}

void print_layer_table(std::FILE* out, const PlanReport& report, bool all_rows) {
  fmt::print(out, "{:>5} {:>9} {:>6} {:>4} {:>6} {:>8} {:>8} {:>3}  {:>6} {:>7} {:>8} {:>5}\n", "layer", "z mm",
             "t mm", "sub", "passes", "dev mm", "est mm", "ok", "convex", "concave", "straight", "mixed");
  const std::size_t n = report.layers.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (!row_shown(out, i, n, all_rows)) continue;
    const ReportLayer& l = report.layers[i];
    const ReportShapes& sh = l.shapes;
    fmt::print(out, "{:>5} {:>9.3f} {:>6.3g} {:>4} {:>6} {:>8.3f} {:>8} {:>3}  {:>6} {:>7} {:>8} {:>5}\n", l.index,
               l.z_bottom_mm, l.thickness_mm, l.sub_slices, l.passes, l.max_deviation_mm,
               fixed_or_dash(l.estimated_deviation_mm, 3), l.within_tolerance ? "yes" : "NO", sh.convex, sh.concave,
               sh.straight, sh.mixed);
  }
  fmt::print(out, "  t: sheet thickness; sub: thin slices read; dev: largest distance between the edge the cuts\n"
                  "  leave and the surface; est: the layering's estimate of it; shape columns count cut stations\n\n");
}

void print_deviation_table(std::FILE* out, const PlanReport& report) {
  const std::string& chosen = report.settings.strategy;
  fmt::print(out, "{:<10} {:>14} {:>9} {:>8}\n", "strategy", "volume mm3", "volume %", "max mm");
  for (const char* name : {"vertical", "sloped", "curved"})
    for (const auto& [strategy, d] : report.deviation)
      if (strategy == name)
        fmt::print(out, "{:<10} {:>14.2f} {:>9.3f} {:>8.3f}{}\n", name, d.volume_mm3, d.volume_pct, d.max_mm,
                   name == chosen ? "  (chosen)" : "");
  fmt::print(out, "  (symmetric difference between stack and model, % of the model's {:.6g} mm3; max: largest distance)\n",
             report.model.volume_mm3);
  if (!report.settings.compare_strategies.value_or(true))
    fmt::print(out, "  (the other strategies on the same layering: --compare-strategies true)\n");
  fmt::print(out, "\n");
}

}  // namespace

void print_plan_tables(std::FILE* out, const PlanReport& report, bool all_rows) {
  print_layer_table(out, report, all_rows);
  print_deviation_table(out, report);

  const ReportStack& st = report.stack;
  std::string sheets;
  for (const auto& [t, count] : st.sheets_used) sheets += fmt::format("{}{} mm x{}", sheets.empty() ? "" : ", ", t, count);
  fmt::print(out, "stack: {} layers ({}), {:.3f} mm high; model {:.3f} mm ({:+.3f} mm)\n", st.layers, sheets,
             st.stack_height_mm, st.model_height_mm, st.height_difference_mm);
  const double tol = report.settings.tolerance_mm;
  for (const ReportShortfall& f : report.shortfalls)
    fmt::print(out, "shortfall: z {:.3f} … {:.3f} mm: no sheet keeps within {} mm; the thinnest reaches {:.3f} mm\n",
               f.z_from_mm, f.z_to_mm, tol, f.deviation_mm);
  const ReportTiming& t = report.timing_s;
  fmt::print(out, "timing: read {:.3f} s, topology {:.3f} s, layering {:.3f} s, bevel {:.3f} s, deviation {:.3f} s, "
                  "write {:.3f} s, total {:.3f} s\n",
             t.read, t.topology, t.layering, t.bevel, t.deviation, t.write, t.total);
}

void print_as_cut_table(std::FILE* out, const ReportAsCut& a, bool all_rows) {
  fmt::print(out, "{:>5} {:>12} {:>12} {:>10} {:>10} {:>6}\n", "layer", "planned %", "as cut %", "planned mm", "as cut mm", "parts");
  const std::size_t n = a.layers.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (!row_shown(out, i, n, all_rows)) continue;
    const ReportAsCutLayer& l = a.layers[i];
    fmt::print(out, "{:>5} {:>12.3f} {:>12.3f} {:>10.3f} {:>10.3f} {:>6}\n", l.layer, l.planned.volume_pct, l.as_cut.volume_pct,
               l.planned.max_mm, l.as_cut.max_mm, freed_of(l.parts_freed, l.parts));
  }
  fmt::print(out, "{:>5} {:>12.3f} {:>12.3f} {:>10.3f} {:>10.3f} {:>6}\n", "all", a.planned.volume_pct, a.as_cut.volume_pct,
             a.planned.max_mm, a.as_cut.max_mm, freed_of(a.parts_freed, a.parts));
  fmt::print(out, "  as cut ({}) beside the plan, both in the same slabs: % of the model's {:.6g} mm3 there;\n"
                  "  mm: largest distance from the cut wall to the model; parts: freed (of placed)\n",
             a.dir, a.model_volume_mm3);
  for (const std::string& s : a.not_freed) fmt::print(out, "  not freed: {}\n", s);
}

}  // namespace lamina::cli
