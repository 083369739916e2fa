#include "kerf_files.hpp"

#include "toml_file.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <optional>
#include <sstream>

namespace lamina::cli {
namespace {

constexpr std::array kColumns{"label", "path_mm", "feed_ratio", "top_width_mm", "bottom_width_mm", "trail_back_mm"};

Error csv_error(const std::string& source, std::size_t line, const std::string& what) {
  return Error{ErrorCode::parse_error, fmt::format("{}:{}: {}", source, line, what)};
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> cells;
  for (std::size_t start = 0;;) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) return cells;
    start = comma + 1;
  }
}

// Column index of each of kColumns in the header.
std::expected<std::array<std::size_t, kColumns.size()>, Error> header_columns(const std::vector<std::string_view>& header,
                                                                              const std::string& source, std::size_t line) {
  std::array<std::optional<std::size_t>, kColumns.size()> at;
  for (std::size_t i = 0; i < header.size(); ++i) {
    const auto known = std::find(kColumns.begin(), kColumns.end(), header[i]);
    if (known == kColumns.end())
      return std::unexpected(csv_error(source, line, fmt::format("unknown column '{}' (known: {})", header[i], fmt::join(kColumns, ", "))));
    auto& slot = at[static_cast<std::size_t>(known - kColumns.begin())];
    if (slot) return std::unexpected(csv_error(source, line, fmt::format("column '{}' given twice", header[i])));
    slot = i;
  }
  std::array<std::size_t, kColumns.size()> out{};
  for (std::size_t c = 0; c < kColumns.size(); ++c) {
    if (!at[c]) return std::unexpected(csv_error(source, line, fmt::format("no column '{}' in the header", kColumns[c])));
    out[c] = *at[c];
  }
  return out;
}

std::expected<double, Error> number_cell(std::string_view cell, std::string_view column, const std::string& source, std::size_t line) {
  if (cell.empty()) return std::unexpected(csv_error(source, line, fmt::format("{}: empty (measure the cut and fill it in)", column)));
  double v = 0.0;
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  if (cell.empty() || ec != std::errc{} || end != cell.data() + cell.size() || !std::isfinite(v))
    return std::unexpected(csv_error(source, line, fmt::format("{}: '{}' is not a number", column, cell)));
  return v;
}

}  // namespace

std::expected<std::vector<KerfMeasurement>, Error> parse_kerf_measurements(std::string_view csv, const std::string& source) {
  std::vector<KerfMeasurement> cuts;
  std::optional<std::array<std::size_t, kColumns.size()>> columns;
  std::size_t header_width = 0, line_no = 0;
  for (std::size_t start = 0; start < csv.size();) {
    const std::size_t nl = csv.find('\n', start);
    const std::string_view line = trim(csv.substr(start, nl == std::string_view::npos ? std::string_view::npos : nl - start));
    start = nl == std::string_view::npos ? csv.size() : nl + 1;
    ++line_no;
    if (line.empty() || line.front() == '#') continue;
    const auto cells = split(line);
    if (!columns) {
      auto c = header_columns(cells, source, line_no);
      if (!c) return std::unexpected(c.error());
      columns = *c;
      header_width = cells.size();
      continue;
    }
    if (cells.size() != header_width)
      return std::unexpected(csv_error(source, line_no, fmt::format("{} values; the header has {} columns", cells.size(), header_width)));
    KerfMeasurement m;
    m.label = std::string(cells[(*columns)[0]]);
    double* fields[] = {&m.path_mm, &m.feed_ratio, &m.top_width_mm, &m.bottom_width_mm, &m.trail_back_mm};
    for (std::size_t c = 1; c < kColumns.size(); ++c) {
      auto v = number_cell(cells[(*columns)[c]], kColumns[c], source, line_no);
      if (!v) return std::unexpected(v.error());
      *fields[c - 1] = *v;
    }
    if (m.label.empty()) m.label = fmt::format("line {}", line_no);
    cuts.push_back(std::move(m));
  }
  if (!columns) return std::unexpected(Error{ErrorCode::parse_error, fmt::format("{}: no header line ({})", source, fmt::join(kColumns, ","))});
  if (cuts.empty()) return std::unexpected(Error{ErrorCode::parse_error, fmt::format("{}: a header and no measurements", source)});
  return cuts;
}

namespace {

struct Coefficient {
  std::string_view key;
  double KerfModel::*field;
  std::string_view comment;
};
constexpr std::array kCoefficients{
    Coefficient{"top_width_mm", &KerfModel::top_width_mm, "w0: top width at r = 0"},
    Coefficient{"top_width_per_ratio_mm", &KerfModel::top_width_per_ratio_mm, "w1: top width grows by w1 · r"},
    Coefficient{"taper_per_ratio", &KerfModel::taper_per_ratio, "k: (w_t - w_b) / h_f = k · (r - r0)"},
    Coefficient{"taper_free_ratio", &KerfModel::taper_free_ratio, "r0: no taper here; reversed below"},
    Coefficient{"trail_back_factor", &KerfModel::trail_back_factor, "c: lag = c · h_f · r^m"},
    Coefficient{"trail_back_exponent", &KerfModel::trail_back_exponent, "m"}};
constexpr std::string_view kOtherKeys = "material, cuts, rms_width_mm, rms_trail_back_mm, measurements";

std::optional<double> as_number(const toml::node& node) {
  if (const auto* i = node.as_integer()) return static_cast<double>(i->get());
  if (const auto* f = node.as_floating_point()) return std::isfinite(f->get()) ? std::optional(f->get()) : std::nullopt;
  return std::nullopt;
}

std::expected<std::pair<std::string, KerfCalibration>, Error> read_kerf(const std::string& source, const toml::table& t) {
  std::pair<std::string, KerfCalibration> out;
  KerfCalibration& k = out.second;
  std::size_t coefficients = 0;
  for (const auto& [key, node] : t) {
    const std::string_view name = key.str();
    const auto c = std::find_if(kCoefficients.begin(), kCoefficients.end(), [&](const Coefficient& x) { return x.key == name; });
    if (c != kCoefficients.end() || name == "rms_width_mm" || name == "rms_trail_back_mm" || name == "cuts") {
      const auto v = as_number(node);
      if (!v) return std::unexpected(toml_error(source, node.source(), fmt::format("{} must be a number", name)));
      if (c != kCoefficients.end()) k.model.*(c->field) = *v, ++coefficients;
      else if (name == "cuts") k.cuts = static_cast<std::int64_t>(*v);
      else (name == "rms_width_mm" ? k.rms_width_mm : k.rms_trail_back_mm) = *v;
    } else if (name == "material" || name == "measurements") {
      const auto* s = node.as_string();
      if (!s || s->get().empty()) return std::unexpected(toml_error(source, node.source(), fmt::format("{} must be a non-empty string", name)));
      (name == "material" ? out.first : k.measurements) = s->get();
    } else {
      std::vector<std::string_view> known;
      for (const Coefficient& x : kCoefficients) known.push_back(x.key);
      return std::unexpected(toml_error(source, key.source(),
                                        fmt::format("unknown key '{}' in [[kerf]] (known: {}, {})", name, fmt::join(known, ", "), kOtherKeys)));
    }
  }
  if (out.first.empty()) return std::unexpected(toml_error(source, t.source(), "[[kerf]] without material"));
  if (coefficients != kCoefficients.size())
    return std::unexpected(toml_error(source, t.source(), fmt::format("[[kerf]] of '{}' lacks some of its {} coefficients", out.first, kCoefficients.size())));
  return out;
}

}  // namespace

std::expected<KerfCalibrations, Error> parse_kerf_toml(std::string_view text, const std::string& source) {
  auto doc = parse_toml(text, source);
  if (!doc) return std::unexpected(doc.error());
  KerfCalibrations out;
  for (const auto& [key, node] : *doc) {
    const auto* list = node.as_array();
    if (key.str() != "kerf" || !list || !list->is_array_of_tables())
      return std::unexpected(toml_error(source, key.source(), fmt::format("unknown key '{}' (the file holds [[kerf]] tables only)", key.str())));
    for (const toml::node& entry : *list) {
      auto k = read_kerf(source, *entry.as_table());
      if (!k) return std::unexpected(k.error());
      if (out.contains(k->first))
        return std::unexpected(toml_error(source, entry.source(), fmt::format("material '{}' given twice", k->first)));
      out.insert(std::move(*k));
    }
  }
  return out;
}

std::string kerf_toml(const KerfCalibrations& calibrations) {
  std::ostringstream os;
  os << "# The jet's kerf per material, fitted from test cuts by `lamina calibrate fit` (docs/jet.md).\n"
        "# Fitting a material again replaces its table. r is the feed over the separation feed, h_f the\n"
        "# jet's path through the sheet (mm).\n";
  for (const auto& [material, k] : calibrations) {
    os << "\n[[kerf]]\nmaterial = " << toml::value<std::string>(material) << "\n";
    for (const Coefficient& c : kCoefficients) os << fmt::format("{} = {:.6g}  # {}\n", c.key, k.model.*(c.field), c.comment);
    os << fmt::format("cuts = {}\nrms_width_mm = {:.4g}\nrms_trail_back_mm = {:.4g}\n", k.cuts, k.rms_width_mm, k.rms_trail_back_mm);
    if (!k.measurements.empty()) os << "measurements = " << toml::value<std::string>(k.measurements) << "\n";
  }
  return os.str();
}

}  // namespace lamina::cli
