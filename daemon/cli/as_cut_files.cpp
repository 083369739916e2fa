#include "as_cut_files.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace lamina::cli {
namespace {

using Json = nlohmann::json;

std::unexpected<Error> parse_error(const std::string& source, const std::string& what) {
  return std::unexpected(Error{ErrorCode::parse_error, fmt::format("{}: {}", source, what)});
}

// A ring as lamina-sim writes it: [x, y, x, y, …], at least three points.
std::expected<Polygon2, std::string> parse_ring(const Json& flat) {
  if (!flat.is_array() || flat.size() % 2 != 0 || flat.size() < 6) return std::unexpected("a ring is [x, y, x, y, …] of 3 points or more");
  Polygon2 ring;
  for (std::size_t i = 0; i < flat.size(); i += 2) {
    if (!flat[i].is_number() || !flat[i + 1].is_number()) return std::unexpected(fmt::format("[{}]: not a number", i));
    ring.emplace_back(flat[i].get<double>(), flat[i + 1].get<double>());
    if (!ring.back().allFinite()) return std::unexpected(fmt::format("[{}]: not finite", i));
  }
  return ring;
}

std::expected<CutSection, std::string> parse_section(const Json& s) {
  if (!s.is_object() || !s.contains("depth_mm") || !s["depth_mm"].is_number() || !s.contains("pieces") || !s["pieces"].is_array())
    return std::unexpected("a section is {\"depth_mm\": number, \"pieces\": [...]}");
  CutSection out{s["depth_mm"].get<double>(), {}};
  for (std::size_t p = 0; p < s["pieces"].size(); ++p) {
    const Json& rings = s["pieces"][p];
    if (!rings.is_array() || rings.empty()) return std::unexpected(fmt::format("pieces[{}]: a piece is a list of rings", p));
    CutPiece piece;
    for (std::size_t r = 0; r < rings.size(); ++r) {
      auto ring = parse_ring(rings[r]);
      if (!ring) return std::unexpected(fmt::format("pieces[{}][{}]{}", p, r, ring.error().starts_with("[") ? ring.error() : ": " + ring.error()));
      piece.rings.push_back(std::move(*ring));
    }
    out.pieces.push_back(std::move(piece));
  }
  return out;
}

}  // namespace

std::string program_fingerprint(std::string_view program) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (const char c : program) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ull;
  }
  return fmt::format("{:016x}", h);
}

std::expected<CutSheet, Error> parse_cut_sheet(std::string_view text, const std::string& source, int sheet,
                                               std::string_view program) {
  const Json j = Json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return parse_error(source, "not a JSON object");
  if (j.value("format", "") != "lamina-sim as-cut 1")
    return parse_error(source, "format: not \"lamina-sim as-cut 1\" (written by lamina-sim --as-cut)");
  const std::string want = program_fingerprint(program);
  if (j.value("program_fnv1a64", "") != want)
    return parse_error(source, fmt::format("cut from another program (fingerprint {}, this plan's is {}): plan with the "
                                           "settings it was cut from, or cut this plan's program",
                                           j.value("program_fnv1a64", "none"), want));
  if (!j.contains("sheet_thickness_mm") || !j["sheet_thickness_mm"].is_number())
    return parse_error(source, "sheet_thickness_mm: missing or not a number");
  if (!j.contains("sections") || !j["sections"].is_array()) return parse_error(source, "sections: missing or not a list");
  CutSheet out{sheet, j["sheet_thickness_mm"].get<double>(), {}};
  for (std::size_t k = 0; k < j["sections"].size(); ++k) {
    auto section = parse_section(j["sections"][k]);
    if (!section) return parse_error(source, fmt::format("sections[{}]: {}", k, section.error()));
    out.sections.push_back(std::move(*section));
  }
  return out;
}

std::expected<std::vector<CutSheet>, Error> read_cut_sheets(const std::string& dir, const CamResult& cam) {
  std::vector<CutSheet> out;
  for (const SheetOutput& s : cam.sheets) {
    const auto path = std::filesystem::path(dir) / fmt::format("sheet-{}.ascut.json", s.sheet.index);
    std::ifstream in(path, std::ios::binary);
    if (!in)
      return std::unexpected(Error{ErrorCode::io_error, fmt::format("--as-cut: {} is missing (cut {} on the machine: "
                                                                    "lamina-sim --as-cut {} --as-cut-out {})",
                                                                    path.string(), s.program_name, s.program_name, path.string())});
    std::stringstream text;
    text << in.rdbuf();
    auto sheet = parse_cut_sheet(text.str(), path.string(), s.sheet.index, s.program.text);
    if (!sheet) return std::unexpected(sheet.error());
    out.push_back(std::move(*sheet));
  }
  return out;
}

ReportAsCut report_as_cut(const AsCutDeviation& d, const std::string& dir) {
  auto figures = [](const VolumeAndDistance& v) {
    return ReportAsCutFigures{v.volume_mm3, v.volume_pct, v.max_mm, {v.max_at_mm.x(), v.max_at_mm.y(), v.max_at_mm.z()}};
  };
  ReportAsCut r{dir, d.model_volume_mm3, figures(d.planned), figures(d.as_cut), d.parts, d.parts_freed, d.not_freed, {}};
  for (const LayerAsCut& l : d.layers)
    r.layers.push_back({l.layer, l.model_volume_mm3, figures(l.planned), figures(l.as_cut), l.parts, l.parts_freed});
  return r;
}

}  // namespace lamina::cli
