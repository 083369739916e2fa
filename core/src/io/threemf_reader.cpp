// 3MF (core specification): a zip whose root model part (found through _rels/.rels, by default
// 3D/3dmodel.model) lists mesh objects (vertices, triangles), component objects (other objects
// under an affine transform) and build items (objects placed in the scene). The soup holds every
// build item's triangles, transformed, in the model's own unit (noted when not millimetre).
// Extensions are ignored; components in other model parts (production extension) are noted and skipped.
#include "lamina/core/mesh_io.hpp"
#include "io/mesh_io_text.hpp"
#include "io/zip_archive.hpp"

#include <fmt/format.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace lamina {
namespace {

// --- A small XML tag scanner: enough for 3MF model and relationship parts. -------------------

struct XmlTag {
  std::string_view name;   // local name (namespace prefix removed)
  std::string_view attrs;  // the raw attribute text
  bool closing = false;    // </name>
  bool empty = false;      // <name ... />
  const char* at = nullptr;
};

class XmlTags {
 public:
  explicit XmlTags(std::string_view text) : begin_(text.data()), p_(text.data()), end_(text.data() + text.size()) {}

  // Next element tag; false at the end. Comments, processing instructions, CDATA and DOCTYPE are skipped.
  std::expected<bool, std::string> next(XmlTag& tag) {
    for (;;) {
      if (p_ >= end_) return false;
      const auto* lt = static_cast<const char*>(std::memchr(p_, '<', static_cast<std::size_t>(end_ - p_)));
      if (lt == nullptr) return false;
      const std::string_view rest(lt, static_cast<std::size_t>(end_ - lt));
      std::string_view terminator;
      if (rest.starts_with("<!--")) terminator = "-->";
      else if (rest.starts_with("<![CDATA[")) terminator = "]]>";
      else if (rest.starts_with("<?")) terminator = "?>";
      else if (rest.starts_with("<!")) terminator = ">";
      if (!terminator.empty()) {
        const std::size_t close = rest.find(terminator, 2);
        if (close == std::string_view::npos) return std::unexpected(unterminated(lt));
        p_ = lt + close + terminator.size();
        continue;
      }
      tag = XmlTag{};
      tag.at = lt;
      const char* q = lt + 1;
      tag.closing = q < end_ && *q == '/';
      if (tag.closing) ++q;
      const char* name_begin = q;
      while (q < end_ && !io_detail::is_space(*q) && *q != '/' && *q != '>') ++q;
      std::string_view name(name_begin, static_cast<std::size_t>(q - name_begin));
      if (const std::size_t colon = name.rfind(':'); colon != std::string_view::npos) name.remove_prefix(colon + 1);
      tag.name = name;
      const char* attrs_begin = q;
      char quote = 0;
      while (q < end_ && (quote != 0 || *q != '>')) {
        if (quote != 0 && *q == quote) quote = 0;
        else if (quote == 0 && (*q == '"' || *q == '\'')) quote = *q;
        ++q;
      }
      if (q == end_) return std::unexpected(unterminated(lt));
      tag.empty = !tag.closing && q > attrs_begin && q[-1] == '/';
      tag.attrs = std::string_view(attrs_begin, static_cast<std::size_t>(q - attrs_begin - (tag.empty ? 1 : 0)));
      p_ = q + 1;
      return true;
    }
  }

  // The line of `at`, counted on from the last position asked about: tags are asked about in
  // order, so a whole file costs one pass (counting from the start each time cost n² for 20,000
  // build items).
  std::size_t line_of(const char* at) const {
    if (at < counted_) {
      counted_ = begin_;
      line_ = 1;
    }
    line_ += static_cast<std::size_t>(std::count(counted_, at, '\n'));
    counted_ = at;
    return line_;
  }

 private:
  std::string unterminated(const char* at) const { return fmt::format("line {}: unterminated XML markup", line_of(at)); }

  const char* begin_;
  const char* p_;
  const char* end_;
  mutable const char* counted_ = begin_;
  mutable std::size_t line_ = 1;
};

// The value of attribute `key` (exact name, prefix included; with `any_prefix`, the local name
// after any "prefix:" matches too), if present.
std::optional<std::string_view> attribute(std::string_view attrs, std::string_view key, bool any_prefix = false) {
  std::size_t i = 0;
  const auto skip_space = [&] {
    while (i < attrs.size() && io_detail::is_space(attrs[i])) ++i;
  };
  while (i < attrs.size()) {
    skip_space();
    const std::size_t name_begin = i;
    while (i < attrs.size() && !io_detail::is_space(attrs[i]) && attrs[i] != '=') ++i;
    const std::string_view name = attrs.substr(name_begin, i - name_begin);
    skip_space();
    if (i >= attrs.size() || attrs[i] != '=') return std::nullopt;
    ++i;
    skip_space();
    if (i >= attrs.size() || (attrs[i] != '"' && attrs[i] != '\'')) return std::nullopt;
    const char quote = attrs[i++];
    const std::size_t close = attrs.find(quote, i);
    if (close == std::string_view::npos) return std::nullopt;
    const std::size_t colon = name.rfind(':');
    if (name == key || (any_prefix && colon != std::string_view::npos && name.substr(colon + 1) == key)) {
      return attrs.substr(i, close - i);
    }
    i = close + 1;
  }
  return std::nullopt;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && io_detail::is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && io_detail::is_space(s.back())) s.remove_suffix(1);
  return s;
}

bool parse_float_value(std::string_view s, float& out) {
  s = trim(s);
  return !s.empty() && io_detail::parse_float(s.data(), s.data() + s.size(), out) == s.data() + s.size();
}

bool parse_int_value(std::string_view s, std::int64_t& out) {
  s = trim(s);
  return !s.empty() && io_detail::parse_int(s.data(), s.data() + s.size(), out) == s.data() + s.size();
}

// --- The model. -------------------------------------------------------------------------------

// 3MF matrices are "m00 m01 m02 m10 m11 m12 m20 m21 m22 m30 m31 m32" acting on row vectors:
// p' = (x y z 1) · M, i.e. p' = linear · p + offset with linear(i, j) = m_ji, offset = (m30 m31 m32).
struct Affine {
  Eigen::Matrix3d linear = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  bool identity = true;

  Affine then_inner(const Affine& inner) const {  // this ∘ inner
    if (identity) return inner;
    if (inner.identity) return *this;
    return Affine{linear * inner.linear, linear * inner.offset + offset, false};
  }
  Eigen::Vector3f apply(const Eigen::Vector3f& p) const {
    if (identity) return p;
    return (linear * p.cast<double>() + offset).cast<float>();
  }
};

std::optional<Affine> parse_transform(std::string_view s) {
  double m[12];
  const char* p = s.data();
  const char* end = s.data() + s.size();
  for (double& v : m) {
    while (p < end && io_detail::is_space(*p)) ++p;
    if (p < end && *p == '+') ++p;
    const auto [next, ec] = std::from_chars(p, end, v);
    if (ec != std::errc{}) return std::nullopt;
    p = next;
  }
  while (p < end && io_detail::is_space(*p)) ++p;
  if (p != end) return std::nullopt;
  Affine a;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a.linear(i, j) = m[3 * j + i];
  a.offset = Eigen::Vector3d(m[9], m[10], m[11]);
  a.identity = a.linear == Eigen::Matrix3d::Identity() && a.offset == Eigen::Vector3d::Zero();
  return a;
}

struct Reference {
  std::int64_t object_id = 0;
  Affine transform;
  std::size_t line = 0;
};

struct Object {
  std::int64_t id = 0;
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<Reference> components;
};

constexpr int kMaxDepth = 32;

// What an object expands to: its triangles and its components', and how deep they nest.
struct Expansion {
  std::uint64_t triangles = 0;  // saturates at UINT64_MAX
  int height = 0;               // 0: no components
};

std::uint64_t saturating_add(std::uint64_t a, std::uint64_t b) { return a > UINT64_MAX - b ? UINT64_MAX : a + b; }

class ModelReader {
 public:
  ModelReader(std::string_view xml, std::string_view name, std::string_view part, const MeshReadOptions& options)
      : tags_(xml), name_(name), part_(part), options_(options), quote_(options.quote_file_text) {}

  std::expected<TriangleSoup, Error> read() {
    if (auto parsed = parse(); !parsed) return std::unexpected(parsed.error());
    if (!seen_model_) {
      return std::unexpected(Error{ErrorCode::parse_error, fmt::format("{}: 3MF model part has no <model> element", name_)});
    }
    // Count first (each object once), so that the soup is allocated once and a build that would
    // expand past the bound is refused before any triangle is made.
    auto total = count_build();
    if (!total) return std::unexpected(total.error());
    TriangleSoup soup;
    soup.format = "3mf";
    soup.corners.reserve(static_cast<std::size_t>(3 * *total));
    for (const Reference& item : items_) emit(item, Affine{}, soup);
    if (soup.corners.empty()) {
      return std::unexpected(Error{ErrorCode::empty_mesh,
                                   fmt::format("{}: 3MF build has no triangles ({} build items, {} objects)", name_,
                                               items_.size(), objects_.size())});
    }
    append_notes(soup);
    return soup;
  }

 private:
  Error error_at(const XmlTag& tag, std::string message) const {
    return error_at_line(tags_.line_of(tag.at), std::move(message));
  }
  Error error_at_line(std::size_t line, std::string message) const {
    return Error{ErrorCode::parse_error, fmt::format("{}: 3MF model line {}: {}", name_, line, message)};
  }

  std::expected<std::int64_t, Error> int_attribute(const XmlTag& tag, std::string_view key) const {
    std::int64_t v = 0;
    const auto value = attribute(tag.attrs, key);
    if (!value || !parse_int_value(*value, v)) {
      return std::unexpected(error_at(tag, fmt::format("<{}> needs an integer attribute '{}'", tag.name, key)));
    }
    return v;
  }

  std::expected<Reference, Error> reference(const XmlTag& tag) const {
    auto id = int_attribute(tag, "objectid");
    if (!id) return std::unexpected(id.error());
    Reference r{*id, Affine{}, tags_.line_of(tag.at)};
    if (const auto t = attribute(tag.attrs, "transform")) {
      const auto affine = parse_transform(*t);
      if (!affine) return std::unexpected(error_at(tag, fmt::format("malformed transform {}", quote_.text(*t, "attribute"))));
      r.transform = *affine;
    }
    return r;
  }

  std::expected<void, Error> parse() {
    XmlTag tag;
    for (;;) {
      auto more = tags_.next(tag);
      if (!more) return std::unexpected(Error{ErrorCode::parse_error, fmt::format("{}: 3MF model {}", name_, more.error())});
      if (!*more) return {};
      if (tag.closing) {
        close(tag.name);
      } else if (auto r = open(tag); !r) {
        return r;
      }
    }
  }

  void close(std::string_view n) {
    if (n == "object") {
      current_ = nullptr;
      in_mesh_ = in_components_ = false;
    } else if (n == "mesh") {
      in_mesh_ = false;
    } else if (n == "components") {
      in_components_ = false;
    } else if (n == "build") {
      in_build_ = false;
    }
  }

  std::expected<void, Error> open(const XmlTag& tag) {
    const std::string_view n = tag.name;
    if (n == "vertex" && current_ != nullptr && in_mesh_) return vertex(tag);
    if (n == "triangle" && current_ != nullptr && in_mesh_) return triangle(tag);
    if (n == "model") {
      seen_model_ = true;
      if (const auto unit = attribute(tag.attrs, "unit")) unit_ = std::string(trim(*unit));
    } else if (n == "object") {
      return object(tag);
    } else if (n == "mesh") {
      in_mesh_ = current_ != nullptr && !tag.empty;
    } else if (n == "components") {
      in_components_ = current_ != nullptr && !tag.empty;
    } else if (n == "component" && current_ != nullptr && in_components_) {
      return reference_to(tag, current_->components);
    } else if (n == "build") {
      in_build_ = !tag.empty;
    } else if (n == "item" && in_build_) {
      return reference_to(tag, items_);
    }
    return {};
  }

  std::expected<void, Error> vertex(const XmlTag& tag) {
    float c[3];
    static constexpr std::string_view keys[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
      const auto v = attribute(tag.attrs, keys[k]);
      if (!v || !parse_float_value(*v, c[k])) {
        return std::unexpected(error_at(tag, fmt::format("<vertex> needs a number attribute '{}'", keys[k])));
      }
    }
    current_->vertices.emplace_back(c[0], c[1], c[2]);
    return {};
  }

  std::expected<void, Error> triangle(const XmlTag& tag) {
    std::array<std::uint32_t, 3> t{};
    static constexpr std::string_view keys[3] = {"v1", "v2", "v3"};
    for (int k = 0; k < 3; ++k) {
      auto v = int_attribute(tag, keys[k]);
      if (!v) return std::unexpected(v.error());
      if (*v < 0 || static_cast<std::uint64_t>(*v) >= current_->vertices.size()) {
        return std::unexpected(error_at(tag, fmt::format("triangle vertex index{} is out of range (object{} has {} "
                                                         "vertices)",
                                                         quote_.value(*v), quote_.value(current_->id),
                                                         current_->vertices.size())));
      }
      t[k] = static_cast<std::uint32_t>(*v);
    }
    current_->triangles.push_back(t);
    return {};
  }

  std::expected<void, Error> object(const XmlTag& tag) {
    auto id = int_attribute(tag, "id");
    if (!id) return std::unexpected(id.error());
    if (!index_.emplace(*id, objects_.size()).second) {
      return std::unexpected(error_at(tag, fmt::format("duplicate object id{}", quote_.value(*id))));
    }
    objects_.push_back(Object{*id, {}, {}, {}});
    current_ = tag.empty ? nullptr : &objects_.back();
    return {};
  }

  // A component or build item; those in other model parts (production extension) are counted.
  std::expected<void, Error> reference_to(const XmlTag& tag, std::vector<Reference>& list) {
    if (attribute(tag.attrs, "path", true)) {
      ++external_;
      return {};
    }
    auto r = reference(tag);
    if (!r) return std::unexpected(r.error());
    list.push_back(*r);
    return {};
  }

  // The object `ref` names, or the error naming the line that names a missing one.
  std::expected<std::size_t, Error> object_of(const Reference& ref) const {
    const auto it = index_.find(ref.object_id);
    if (it == index_.end()) {
      return std::unexpected(error_at_line(ref.line, fmt::format("object{} does not exist", quote_.value(ref.object_id))));
    }
    return it->second;
  }

  Error too_deep(const Reference& ref) const {
    return error_at_line(ref.line, fmt::format("components nest deeper than {} (a cycle?)", kMaxDepth));
  }

  // What `ref`'s object expands to, each object worked out once (memo_); a reference at `depth`
  // whose object nests too deep for it, or that closes a cycle, is an error.
  std::expected<Expansion, Error> expand(const Reference& ref, int depth) {
    auto index = object_of(ref);
    if (!index) return std::unexpected(index.error());
    Memo& m = memo_[*index];
    if (m.state == Memo::expanding) return std::unexpected(too_deep(ref));
    if (m.state == Memo::done) {
      if (depth + m.e.height > kMaxDepth) return std::unexpected(too_deep(ref));
      return m.e;
    }
    if (depth > kMaxDepth) return std::unexpected(too_deep(ref));
    m.state = Memo::expanding;
    Expansion e{objects_[*index].triangles.size(), 0};
    for (const Reference& c : objects_[*index].components) {
      auto sub = expand(c, depth + 1);
      if (!sub) return sub;
      e.triangles = saturating_add(e.triangles, sub->triangles);
      e.height = std::max(e.height, sub->height + 1);
    }
    memo_[*index] = Memo{e, Memo::done};
    return e;
  }

  // The build's triangle count, refused above options_.max_triangles.
  std::expected<std::uint64_t, Error> count_build() {
    memo_.assign(objects_.size(), Memo{});
    std::uint64_t total = 0;
    const Reference* largest = nullptr;
    std::uint64_t largest_count = 0;
    for (const Reference& item : items_) {
      auto e = expand(item, 0);
      if (!e) return std::unexpected(e.error());
      total = saturating_add(total, e->triangles);
      if (largest == nullptr || e->triangles > largest_count) {
        largest = &item;
        largest_count = e->triangles;
      }
    }
    if (total <= options_.max_triangles) return total;
    const auto count = [](std::uint64_t n) {
      return n == UINT64_MAX ? fmt::format("more than {}", n - 1) : fmt::format("{}", n);
    };
    return std::unexpected(Error{
        ErrorCode::limit_exceeded,
        fmt::format("{}: 3MF model part {}: the build expands to {} triangles (components within components, times "
                    "build items), over the limit of {} (MeshReadOptions::max_triangles); the largest is the build "
                    "item on line {} (object{}, {} triangles)",
                    name_, part_label(), count(total), options_.max_triangles, largest->line,
                    quote_.value(largest->object_id), count(largest_count))});
  }

  // Appends the triangles of `ref` (counted and checked by count_build) under `outer`.
  void emit(const Reference& ref, const Affine& outer, TriangleSoup& soup) const {
    const Object& object = objects_[index_.at(ref.object_id)];
    const Affine transform = outer.then_inner(ref.transform);
    for (const auto& t : object.triangles)
      for (std::uint32_t v : t) soup.corners.push_back(transform.apply(object.vertices[v]));
    for (const Reference& c : object.components) emit(c, transform, soup);
  }

  void append_notes(TriangleSoup& soup) const {
    if (unit_ != "millimeter") {
      soup.notes.push_back({"units", fmt::format("{}: 3MF model unit is {} (coordinates kept as stored)", name_,
                                                 quote_.either(io_detail::quote_excerpt(unit_), "not millimeter"))});
    }
    if (external_ > 0) {
      soup.notes.push_back({"3mf_external_skipped",
                            fmt::format("{}: {} components or items in other model parts (production extension) "
                                        "were skipped",
                                        name_, external_)});
    }
  }

  struct Memo {
    enum State : std::uint8_t { unvisited, expanding, done };
    Expansion e;
    State state = unvisited;
  };

  std::string part_label() const {
    return quote_.quoting() ? io_detail::quote_excerpt(part_, 200) : "(" + quote_.text(part_, "a name") + ")";
  }

  XmlTags tags_;
  std::string_view name_;
  std::string_view part_;
  const MeshReadOptions& options_;
  io_detail::FileQuote quote_;
  std::vector<Object> objects_;
  std::unordered_map<std::int64_t, std::size_t> index_;
  std::vector<Reference> items_;
  std::vector<Memo> memo_;
  Object* current_ = nullptr;
  bool in_mesh_ = false, in_components_ = false, in_build_ = false;
  std::string unit_ = "millimeter";
  std::size_t external_ = 0;
  bool seen_model_ = false;
};

bool iequal_names(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (io_detail::ascii_lower(a[i]) != io_detail::ascii_lower(b[i])) return false;
  return true;
}

constexpr std::string_view kDefaultModelPart = "3D/3dmodel.model";

// The root model part named by the package relationships, else the conventional path.
std::expected<std::string, Error> model_part_name(std::span<const std::byte> zip,
                                                  const std::vector<io_detail::ZipEntry>& entries, std::string_view name,
                                                  const MeshReadOptions& options) {
  std::string part(kDefaultModelPart);
  for (const auto& e : entries) {
    if (!iequal_names(e.name, "_rels/.rels")) continue;
    auto rels = io_detail::read_zip_entry(zip, e, name, options);
    if (!rels) return std::unexpected(rels.error());
    XmlTags tags(*rels);
    XmlTag tag;
    for (auto more = tags.next(tag); more && *more; more = tags.next(tag)) {
      if (tag.closing || tag.name != "Relationship") continue;
      const auto type = attribute(tag.attrs, "Type");
      const auto target = attribute(tag.attrs, "Target");
      if (type && target && type->ends_with("/3dmodel")) {
        std::string_view t = trim(*target);
        while (t.starts_with('/')) t.remove_prefix(1);
        part = std::string(t);
        break;
      }
    }
    break;
  }
  return part;
}

}  // namespace

std::expected<TriangleSoup, Error> parse_3mf(std::span<const std::byte> bytes, std::string_view name,
                                             const MeshReadOptions& options) {
  const io_detail::FileQuote quote(options.quote_file_text);
  auto entries = io_detail::list_zip(bytes, name, quote);
  if (!entries) return std::unexpected(entries.error());
  if (!io_detail::zip_support_compiled()) {
    return std::unexpected(Error{ErrorCode::unsupported,
                                 fmt::format("{}: 3MF is not supported yet (this build has no zlib)", name)});
  }
  const auto part = model_part_name(bytes, *entries, name, options);
  if (!part) return std::unexpected(part.error());
  const auto entry = std::find_if(entries->begin(), entries->end(),
                                  [&](const io_detail::ZipEntry& e) { return iequal_names(e.name, *part); });
  if (entry == entries->end()) {
    // The conventional name is ours to quote; one from the relationships is the file's.
    const std::string which = *part == kDefaultModelPart || quote.quoting()
                                  ? fmt::format("'{}'", *part)
                                  : fmt::format("named by _rels/.rels ({})", quote.text(*part, "a name"));
    return std::unexpected(Error{ErrorCode::unknown_format,
                                 fmt::format("{}: not a 3MF file: the zip has no model part {}", name, which)});
  }
  auto xml = io_detail::read_zip_entry(bytes, *entry, name, options);
  if (!xml) return std::unexpected(xml.error());
  return ModelReader(*xml, name, *part, options).read();
}

}  // namespace lamina
