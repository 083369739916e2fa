// report.json ⇄ PlanReport (plan_report.hpp). Every struct of the report is listed once, as a
// table of (key, member); the writer and the reader both walk that table, so the file and the
// struct cannot drift apart. The reader is strict: every key must be there, with its type, and
// no other key — a mismatch is a bug between writer and reader, said with the key's path.
#include "lamina/core/plan_report.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <tuple>
#include <type_traits>

namespace lamina {
namespace {

using Json = nlohmann::ordered_json;

template <class S, class T>
struct Field {
  const char* key;
  T S::*member;
};
template <class S, class T>
Field(const char*, T S::*) -> Field<S, T>;

// The tables. Order is the file's key order.
template <class S>
struct Fields;

template <>
struct Fields<ReportCadSolid> {
  static constexpr auto all = std::tuple{Field{"name", &ReportCadSolid::name}, Field{"faces", &ReportCadSolid::faces},
                                         Field{"triangles", &ReportCadSolid::triangles}};
};
template <>
struct Fields<ReportCad> {
  static constexpr auto all =
      std::tuple{Field{"length_unit", &ReportCad::length_unit}, Field{"chord_tolerance_mm", &ReportCad::chord_tolerance_mm},
                 Field{"surface_normals", &ReportCad::surface_normals}, Field{"solids", &ReportCad::solids},
                 Field{"surface_kinds", &ReportCad::surface_kinds}};
};
template <>
struct Fields<ReportDeviationReference> {
  using R = ReportDeviationReference;
  static constexpr auto all = std::tuple{Field{"file", &R::file}, Field{"format", &R::format},
                                         Field{"triangles", &R::triangles},
                                         Field{"chord_tolerance_mm", &R::chord_tolerance_mm}};
};
template <>
struct Fields<ReportModel> {
  static constexpr auto all = std::tuple{Field{"file", &ReportModel::file}, Field{"format", &ReportModel::format},
                                         Field{"triangles", &ReportModel::triangles},
                                         Field{"volume_mm3", &ReportModel::volume_mm3},
                                         Field{"height_mm", &ReportModel::height_mm}, Field{"cad", &ReportModel::cad},
                                         Field{"deviation_reference", &ReportModel::deviation_reference}};
  static constexpr bool omit_empty(std::string_view key) { return key == "cad" || key == "deviation_reference"; }
};
template <>
struct Fields<ReportStockSheet> {
  static constexpr auto all =
      std::tuple{Field{"thickness_mm", &ReportStockSheet::thickness_mm}, Field{"width_mm", &ReportStockSheet::width_mm},
                 Field{"length_mm", &ReportStockSheet::length_mm}, Field{"count", &ReportStockSheet::count},
                 Field{"material", &ReportStockSheet::material}, Field{"slot", &ReportStockSheet::slot}};
  static constexpr bool omit_empty(std::string_view key) { return key == "slot"; }
};
template <>
struct Fields<ReportSettings> {
  using S = ReportSettings;
  static constexpr auto all =
      std::tuple{Field{"stock", &S::stock},         Field{"stock_source", &S::stock_source},
                 Field{"thicknesses_mm", &S::thicknesses_mm}, Field{"bond_mm", &S::bond_mm},
                 Field{"sub_slice_mm", &S::sub_slice_mm},     Field{"tolerance_mm", &S::tolerance_mm},
                 Field{"tilt_max_deg", &S::tilt_max_deg},     Field{"side", &S::side},
                 Field{"strategy", &S::strategy},             Field{"layering", &S::layering},
                 Field{"deviation_step_mm", &S::deviation_step_mm},
                 Field{"compare_strategies", &S::compare_strategies}, Field{"axis", &S::axis},
                 Field{"direction", &S::direction},           Field{"units", &S::units}};
  static constexpr bool omit_empty(std::string_view key) { return key == "compare_strategies"; }
};
template <>
struct Fields<ReportShapes> {
  using S = ReportShapes;
  static constexpr auto all = std::tuple{Field{"convex", &S::convex}, Field{"concave", &S::concave},
                                         Field{"straight", &S::straight}, Field{"mixed", &S::mixed},
                                         Field{"empty", &S::empty}};
};
template <>
struct Fields<ReportLayer> {
  using S = ReportLayer;
  static constexpr auto all = std::tuple{
      Field{"index", &S::index},
      Field{"z_bottom_mm", &S::z_bottom_mm},
      Field{"thickness_mm", &S::thickness_mm},
      Field{"sub_slices", &S::sub_slices},
      Field{"passes", &S::passes},
      Field{"max_deviation_mm", &S::max_deviation_mm},
      Field{"profile_deviation_mm", &S::profile_deviation_mm},
      Field{"within_tolerance", &S::within_tolerance},
      Field{"gouge_shift_mm", &S::gouge_shift_mm},
      Field{"gouge_left_mm", &S::gouge_left_mm},
      Field{"estimated_deviation_mm", &S::estimated_deviation_mm},
      Field{"outlines", &S::outlines},
      Field{"stations", &S::stations},
      Field{"shapes", &S::shapes},
      Field{"outline_simplified", &S::outline_simplified}};
  static constexpr bool omit_empty(std::string_view key) { return key == "outline_simplified"; }
};
template <>
struct Fields<ReportStack> {
  using S = ReportStack;
  static constexpr auto all = std::tuple{Field{"layers", &S::layers}, Field{"model_height_mm", &S::model_height_mm},
                                         Field{"stack_height_mm", &S::stack_height_mm},
                                         Field{"height_difference_mm", &S::height_difference_mm},
                                         Field{"sheets_used", &S::sheets_used}};
};
template <>
struct Fields<ReportShortfall> {
  using S = ReportShortfall;
  static constexpr auto all = std::tuple{Field{"z_from_mm", &S::z_from_mm}, Field{"z_to_mm", &S::z_to_mm},
                                         Field{"deviation_mm", &S::deviation_mm}};
};
template <>
struct Fields<ReportDeviation> {
  using S = ReportDeviation;
  static constexpr auto all = std::tuple{Field{"volume_mm3", &S::volume_mm3}, Field{"volume_pct", &S::volume_pct},
                                         Field{"max_mm", &S::max_mm}, Field{"max_at_mm", &S::max_at_mm},
                                         Field{"stack_volume_mm3", &S::stack_volume_mm3}};
};
template <>
struct Fields<ReportTiming> {
  using S = ReportTiming;
  static constexpr auto all =
      std::tuple{Field{"read", &S::read},   Field{"topology", &S::topology},   Field{"layering", &S::layering},
                 Field{"bevel", &S::bevel}, Field{"deviation", &S::deviation}, Field{"write", &S::write},
                 Field{"total", &S::total}};
};
template <>
struct Fields<ReportCamTiming> {
  using S = ReportCamTiming;
  static constexpr auto all = std::tuple{Field{"parts", &S::parts}, Field{"nest", &S::nest},
                                         Field{"toolpath", &S::toolpath}, Field{"post", &S::post},
                                         Field{"svg", &S::svg}};
};
template <>
struct Fields<ReportHead> {
  using S = ReportHead;
  static constexpr auto all = std::tuple{Field{"pivot_mm", &S::pivot_mm}, Field{"a_sign", &S::a_sign},
                                         Field{"c_sign", &S::c_sign}, Field{"c_offset_deg", &S::c_offset_deg}};
};
template <>
struct Fields<ReportCam> {
  using S = ReportCam;
  static constexpr auto all = std::tuple{
      Field{"machine_file", &S::machine_file}, Field{"materials_file", &S::materials_file}, Field{"nest", &S::nest},
      Field{"spacing_mm", &S::spacing_mm},     Field{"margin_mm", &S::margin_mm},           Field{"fill_holes", &S::fill_holes},
      Field{"post", &S::post},                 Field{"rtcp", &S::rtcp},                     Field{"head", &S::head},
      Field{"feed_model", &S::feed_model},
      Field{"quality", &S::quality},           Field{"kerf_mm", &S::kerf_mm},               Field{"lead_in_mm", &S::lead_in_mm},
      Field{"lead_out_mm", &S::lead_out_mm},   Field{"pierce_dwell_s", &S::pierce_dwell_s}, Field{"microjoints", &S::microjoints},
      Field{"microjoint_width_mm", &S::microjoint_width_mm}, Field{"dowels", &S::dowels},
      Field{"dowel_diameter_mm", &S::dowel_diameter_mm},     Field{"parts", &S::parts},
      Field{"timing_s", &S::timing_s}, Field{"jet_compensation", &S::jet_compensation}, Field{"kerf_file", &S::kerf_file},
      Field{"corner_error_mm", &S::corner_error_mm}, Field{"inside_corners", &S::inside_corners},
      Field{"a_max_deg_per_min", &S::a_max_deg_per_min}, Field{"c_max_deg_per_min", &S::c_max_deg_per_min}};
  static constexpr bool omit_empty(std::string_view key) {
    return key == "head" || key == "jet_compensation" || key == "kerf_file" || key == "corner_error_mm" ||
           key == "inside_corners" || key == "a_max_deg_per_min" || key == "c_max_deg_per_min";
  }
};
template <>
struct Fields<ReportPart> {
  using S = ReportPart;
  static constexpr auto all = std::tuple{Field{"layer", &S::layer}, Field{"island", &S::island}, Field{"label", &S::label},
                                         Field{"x_mm", &S::x_mm},   Field{"y_mm", &S::y_mm},
                                         Field{"rotation_deg", &S::rotation_deg}, Field{"inside", &S::inside},
                                         Field{"dowels", &S::dowels}};
};
template <>
struct Fields<ReportSheetTime> {
  using S = ReportSheetTime;
  static constexpr auto all =
      std::tuple{Field{"cutting", &S::cutting}, Field{"rapids", &S::rapids}, Field{"pierces", &S::pierces}};
};
template <>
struct Fields<ReportContour> {
  using S = ReportContour;
  static constexpr auto all =
      std::tuple{Field{"index", &S::index}, Field{"line", &S::line}, Field{"last_cut_line", &S::last_cut_line}};
};
template <>
struct Fields<ReportSheet> {
  using S = ReportSheet;
  static constexpr auto all = std::tuple{
      Field{"index", &S::index},
      Field{"thickness_mm", &S::thickness_mm},
      Field{"width_mm", &S::width_mm},
      Field{"length_mm", &S::length_mm},
      Field{"material", &S::material},
      Field{"slot", &S::slot},
      Field{"program", &S::program},
      Field{"svg", &S::svg},
      Field{"estimated_time_s", &S::estimated_time_s},
      Field{"time_s", &S::time_s},
      Field{"cut_length_mm", &S::cut_length_mm},
      Field{"pierces", &S::pierces},
      Field{"contours", &S::contours},
      Field{"microjoints", &S::microjoints},
      Field{"utilisation", &S::utilisation},
      Field{"program_bytes", &S::program_bytes},
      Field{"program_lines", &S::program_lines},
      Field{"five_axis_moves", &S::five_axis_moves},
      Field{"bytes_per_five_axis_move", &S::bytes_per_five_axis_move},
      Field{"parts", &S::parts},
      Field{"setup_lines", &S::setup_lines},
      Field{"contour_lines", &S::contour_lines},
      Field{"jet_compensation", &S::jet_compensation},
      Field{"jet_tilt_limited", &S::jet_tilt_limited},
      Field{"jet_corners_floored", &S::jet_corners_floored}};
  static constexpr bool omit_empty(std::string_view key) {
    return key == "slot" || key == "jet_compensation" || key == "jet_tilt_limited" || key == "jet_corners_floored";
  }
};
template <>
struct Fields<ReportAsCutFigures> {
  using S = ReportAsCutFigures;
  static constexpr auto all =
      std::tuple{Field{"volume_mm3", &S::volume_mm3}, Field{"volume_pct", &S::volume_pct}, Field{"max_mm", &S::max_mm},
                 Field{"max_at_mm", &S::max_at_mm}};
};
template <>
struct Fields<ReportAsCutLayer> {
  using S = ReportAsCutLayer;
  static constexpr auto all = std::tuple{Field{"layer", &S::layer},   Field{"model_volume_mm3", &S::model_volume_mm3},
                                         Field{"planned", &S::planned}, Field{"as_cut", &S::as_cut},
                                         Field{"parts", &S::parts},   Field{"parts_freed", &S::parts_freed}};
};
template <>
struct Fields<ReportAsCut> {
  using S = ReportAsCut;
  static constexpr auto all =
      std::tuple{Field{"dir", &S::dir},       Field{"model_volume_mm3", &S::model_volume_mm3}, Field{"planned", &S::planned},
                 Field{"as_cut", &S::as_cut}, Field{"parts", &S::parts},                       Field{"parts_freed", &S::parts_freed},
                 Field{"not_freed", &S::not_freed}, Field{"layers", &S::layers}};
};
template <>
struct Fields<PlanReport> {
  using S = PlanReport;
  static constexpr auto all = std::tuple{
      Field{"model", &S::model},           Field{"settings", &S::settings},     Field{"layers", &S::layers},
      Field{"stack", &S::stack},           Field{"shortfalls", &S::shortfalls}, Field{"deviation", &S::deviation},
      Field{"warnings", &S::warnings},     Field{"timing_s", &S::timing_s},     Field{"cam", &S::cam},
      Field{"sheets", &S::sheets},         Field{"as_cut", &S::as_cut}};
  // Members that are left out of the file when empty, rather than written as null.
  static constexpr bool omit_empty(std::string_view key) { return key == "cam" || key == "sheets" || key == "as_cut"; }
};

template <class T>
concept Record = requires { Fields<T>::all; };
template <class T>
struct is_optional : std::false_type {};
template <class T>
struct is_optional<std::optional<T>> : std::true_type {};
template <class T>
struct is_vector : std::false_type {};
template <class T>
struct is_vector<std::vector<T>> : std::true_type {};
template <class T>
struct is_named_list : std::false_type {};  // vector<pair<string, T>>: an object with keys of our choosing
template <class T>
struct is_named_list<std::vector<std::pair<std::string, T>>> : std::true_type {};

template <class S>
constexpr bool omits_when_empty(std::string_view key) {
  if constexpr (requires { Fields<S>::omit_empty(key); })
    return Fields<S>::omit_empty(key);
  else
    return false;
}

// ---- writing ----

template <class T>
Json to_json(const T& value);

template <class S, class F>
void put_member(Json& j, const S& record, const F& field) {
  const auto& value = record.*field.member;
  if constexpr (is_optional<std::remove_cvref_t<decltype(value)>>::value)
    if (omits_when_empty<S>(field.key) && !value) return;
  j[field.key] = to_json(value);
}

template <Record S>
Json record_to_json(const S& record) {
  Json j = Json::object();
  std::apply([&](const auto&... field) { (put_member(j, record, field), ...); }, Fields<S>::all);
  return j;
}

template <class T>
Json to_json(const T& value) {
  if constexpr (Record<T>) {
    return record_to_json(value);
  } else if constexpr (is_optional<T>::value) {
    return value ? to_json(*value) : Json(nullptr);
  } else if constexpr (is_named_list<T>::value) {
    Json j = Json::object();
    for (const auto& [key, item] : value) j[key] = to_json(item);
    return j;
  } else if constexpr (is_vector<T>::value || std::is_same_v<T, std::array<double, 3>>) {
    Json j = Json::array();
    for (const auto& item : value) j.push_back(to_json(item));
    return j;
  } else {
    return Json(value);
  }
}

// ---- reading ----

struct Reader {
  std::string error;  // the first mismatch, with its path

  bool fail(const std::string& path, const std::string& what) {
    if (error.empty()) error = fmt::format("report.json: {}: {}", path.empty() ? "(top)" : path, what);
    return false;
  }
  static const char* kind(const Json& j) {
    return j.is_null() ? "null" : j.is_boolean() ? "a boolean" : j.is_number() ? "a number" : j.is_string() ? "a string"
           : j.is_array() ? "an array" : "an object";
  }
  bool expect(bool ok, const Json& j, const std::string& path, const char* wanted) {
    return ok || fail(path, fmt::format("expected {}, found {}", wanted, kind(j)));
  }

  template <class T>
  bool read(const Json& j, const std::string& path, T& out) {
    if constexpr (Record<T>) {
      return read_record(j, path, out);
    } else if constexpr (is_optional<T>::value) {
      if (j.is_null()) {
        out.reset();
        return true;
      }
      return read(j, path, out.emplace());
    } else if constexpr (is_named_list<T>::value) {
      if (!expect(j.is_object(), j, path, "an object")) return false;
      out.clear();
      for (const auto& [key, item] : j.items()) {
        out.emplace_back(key, typename T::value_type::second_type{});
        if (!read(item, path + "." + key, out.back().second)) return false;
      }
      return true;
    } else if constexpr (is_vector<T>::value) {
      if (!expect(j.is_array(), j, path, "an array")) return false;
      out.assign(j.size(), {});
      for (std::size_t i = 0; i < j.size(); ++i)
        if (!read(j[i], fmt::format("{}[{}]", path, i), out[i])) return false;
      return true;
    } else if constexpr (std::is_same_v<T, std::array<double, 3>>) {
      if (!expect(j.is_array() && j.size() == 3, j, path, "an array of 3 numbers")) return false;
      for (std::size_t i = 0; i < 3; ++i)
        if (!read(j[i], fmt::format("{}[{}]", path, i), out[i])) return false;
      return true;
    } else if constexpr (std::is_same_v<T, bool>) {
      if (!expect(j.is_boolean(), j, path, "a boolean")) return false;
      out = j.get<bool>();
      return true;
    } else if constexpr (std::is_same_v<T, std::int64_t>) {
      if (!expect(j.is_number_integer(), j, path, "an integer")) return false;
      out = j.get<std::int64_t>();
      return true;
    } else if constexpr (std::is_same_v<T, double>) {
      if (!expect(j.is_number(), j, path, "a number")) return false;
      out = j.get<double>();
      return true;
    } else {
      static_assert(std::is_same_v<T, std::string>);
      if (!expect(j.is_string(), j, path, "a string")) return false;
      out = j.get<std::string>();
      return true;
    }
  }

  template <class S>
  bool read_record(const Json& j, const std::string& path, S& out) {
    if (!expect(j.is_object(), j, path, "an object")) return false;
    std::size_t known = 0;
    const bool ok = std::apply(
        [&](const auto&... field) {
          return (read_member<S>(j, path, field.key, out.*field.member, known) && ...);
        },
        Fields<S>::all);
    if (!ok) return false;
    if (known == j.size()) return true;
    for (const auto& [key, value] : j.items()) {
      bool listed = false;
      std::apply([&](const auto&... field) { listed = ((key == field.key) || ...); }, Fields<S>::all);
      if (!listed) return fail(path.empty() ? key : path + "." + key, "not a key of the report");
    }
    return true;
  }

  template <class S, class T>
  bool read_member(const Json& j, const std::string& path, const char* key, T& out, std::size_t& known) {
    const std::string here = path.empty() ? key : path + "." + key;
    const auto it = j.find(key);
    if (it == j.end()) {
      if constexpr (is_optional<T>::value)
        if (omits_when_empty<S>(key)) {
          out.reset();
          return true;
        }
      return fail(here, "missing");
    }
    ++known;
    return read(*it, here, out);
  }
};

}  // namespace

std::string plan_report_json(const PlanReport& report) { return to_json(report).dump(2) + "\n"; }
std::string report_cad_json(const ReportCad& cad) { return to_json(cad).dump(); }

std::expected<PlanReport, Error> parse_plan_report(std::string_view text) {
  Json j;
  try {
    j = Json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    return std::unexpected(Error{ErrorCode::parse_error, fmt::format("report.json: not JSON: {}", e.what())});
  }
  PlanReport report;
  Reader reader;
  if (!reader.read(j, "", report)) return std::unexpected(Error{ErrorCode::parse_error, reader.error});
  return report;
}

}  // namespace lamina
