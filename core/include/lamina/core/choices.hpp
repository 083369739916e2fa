#pragma once
// The choices a plan offers — post dialects, nesting methods, feed models, bevel strategies, cut
// sides, layering methods — registered once, in the library that owns each (issue 18): a table
// of rows (value, name as a person types it, one line of what it is, and its traits). The CLI's
// option checks, the machine-file loader, laminad's plan settings and the reports read names
// through these tables; adding a row is all a new choice needs, and a name no row has is an
// error that lists the known ones — never a silent fall back to a default.
#include "lamina/core/error.hpp"

#include <expected>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace lamina {

struct NoTraits {};

template <class E, class Traits = NoTraits>
struct Choice {
  E value;
  std::string_view name;     // as typed: command line, config files, laminad's settings
  std::string_view summary;  // one line for help texts
  Traits traits{};
};

template <class E, class Traits = NoTraits>
class ChoiceTable {
 public:
  using Row = Choice<E, Traits>;
  constexpr ChoiceTable(std::string_view what, std::span<const Row> rows) : what_(what), rows_(rows) {}

  std::string_view what() const { return what_; }  // "post dialect"
  std::span<const Row> rows() const { return rows_; }

  const Row* find(std::string_view name) const {
    for (const Row& r : rows_)
      if (r.name == name) return &r;
    return nullptr;
  }
  const Row* find(E value) const {
    for (const Row& r : rows_)
      if (r.value == value) return &r;
    return nullptr;
  }
  const char* name_of(E value) const {  // rows' names are literals: NUL-terminated
    const Row* r = find(value);
    return r ? r->name.data() : "?";
  }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const Row& r : rows_) out.emplace_back(r.name);
    return out;
  }
  std::string names_text() const {  // "a, b, c"
    std::string out;
    for (const Row& r : rows_) out += (out.empty() ? "" : ", ") + std::string(r.name);
    return out;
  }
  // invalid_argument: "unknown post dialect 'x' (known: grblhal, fanuc, linuxcnc)".
  std::expected<E, Error> parse(std::string_view name) const {
    if (const Row* r = find(name)) return r->value;
    return std::unexpected(Error{ErrorCode::invalid_argument, "unknown " + std::string(what_) + " '" + std::string(name) +
                                                                  "' (known: " + names_text() + ")"});
  }

 private:
  std::string_view what_;
  std::span<const Row> rows_;
};

}  // namespace lamina
