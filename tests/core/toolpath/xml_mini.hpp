#pragma once
// A tiny, strict XML reader for tests: elements, attributes, text, comments and the XML
// declaration; entities limited to the five predefined ones and character references. Anything
// else (unbalanced or mismatched tags, a raw '<' or a bad '&' in text or attribute values,
// duplicate attributes, trailing content) is an error — so a malformed document fails the test.
#include <cctype>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace xml_mini {

struct Element {
  std::string name;
  std::map<std::string, std::string> attrs;
  std::string text;  // all direct text content, entities decoded
  std::vector<Element> children;

  std::string attr(const std::string& key) const {
    auto it = attrs.find(key);
    return it == attrs.end() ? std::string() : it->second;
  }
  bool has_class(const std::string& cls) const { return attr("class") == cls; }

  // Every element below (and including) this one that satisfies pred, in document order.
  void collect(const std::function<bool(const Element&)>& pred, std::vector<const Element*>& out) const {
    if (pred(*this)) out.push_back(this);
    for (const auto& c : children) c.collect(pred, out);
  }
  std::vector<const Element*> find(const std::string& name, const std::string& cls = {}) const {
    std::vector<const Element*> out;
    collect([&](const Element& e) { return e.name == name && (cls.empty() || e.has_class(cls)); }, out);
    return out;
  }
};

struct Result {
  std::optional<Element> root;
  std::string error;
};

class Parser {
 public:
  explicit Parser(std::string_view s) : s_(s) {}

  Result run() {
    Result r;
    skip_misc(true);
    if (!fail_.empty()) return {std::nullopt, fail_};
    auto root = element();
    if (!root) return {std::nullopt, fail_};
    skip_misc(false);
    if (!fail_.empty()) return {std::nullopt, fail_};
    if (i_ != s_.size()) return {std::nullopt, "content after the root element at " + std::to_string(i_)};
    r.root = std::move(root);
    return r;
  }

 private:
  bool starts(std::string_view p) const { return s_.substr(i_, p.size()) == p; }
  void ws() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  bool fail(const std::string& m) {
    if (fail_.empty()) fail_ = m + " at offset " + std::to_string(i_);
    return false;
  }
  bool skip_until(std::string_view end) {
    const auto k = s_.find(end, i_);
    if (k == std::string_view::npos) return fail("unterminated construct");
    i_ = k + end.size();
    return true;
  }
  void skip_misc(bool allow_decl) {
    for (;;) {
      ws();
      if (allow_decl && i_ == 0 && starts("<?xml")) {
        if (!skip_until("?>")) return;
      } else if (starts("<!--")) {
        if (!skip_until("-->")) return;
      } else {
        return;
      }
    }
  }
  static bool name_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == ':' || c == '-' || c == '.';
  }
  std::string name() {
    const std::size_t b = i_;
    while (i_ < s_.size() && name_char(s_[i_])) ++i_;
    return std::string(s_.substr(b, i_ - b));
  }
  // Decodes s_[b, e); false on a raw '<' or an unknown/unterminated entity.
  bool decode(std::size_t b, std::size_t e, std::string& out) {
    for (std::size_t k = b; k < e; ++k) {
      const char c = s_[k];
      if (c == '<') return fail("raw '<' in text or attribute");
      if (c != '&') {
        out += c;
        continue;
      }
      const auto semi = s_.find(';', k);
      if (semi == std::string_view::npos || semi >= e) return fail("unterminated entity");
      const std::string_view ent = s_.substr(k + 1, semi - k - 1);
      if (ent == "amp") out += '&';
      else if (ent == "lt") out += '<';
      else if (ent == "gt") out += '>';
      else if (ent == "quot") out += '"';
      else if (ent == "apos") out += '\'';
      else if (ent.size() > 1 && ent[0] == '#') {
        const bool hex = ent[1] == 'x';
        const std::string digits(ent.substr(hex ? 2 : 1));
        if (digits.empty()) return fail("empty character reference");
        const long v = std::stol(digits, nullptr, hex ? 16 : 10);
        if (v < 0x80) out += static_cast<char>(v);
        else out += '?';
      } else {
        return fail("unknown entity &" + std::string(ent) + ";");
      }
      k = semi;
    }
    return true;
  }
  std::optional<Element> element() {
    if (!starts("<")) return fail("expected '<'"), std::nullopt;
    ++i_;
    Element e;
    e.name = name();
    if (e.name.empty()) return fail("empty tag name"), std::nullopt;
    for (;;) {
      const std::size_t before = i_;
      ws();
      if (starts("/>")) {
        i_ += 2;
        return e;
      }
      if (starts(">")) {
        ++i_;
        break;
      }
      if (i_ == before) return fail("expected whitespace before an attribute"), std::nullopt;
      const std::string key = name();
      if (key.empty()) return fail("bad attribute name"), std::nullopt;
      ws();
      if (!starts("=")) return fail("expected '='"), std::nullopt;
      ++i_;
      ws();
      if (i_ >= s_.size() || (s_[i_] != '"' && s_[i_] != '\'')) return fail("unquoted attribute"), std::nullopt;
      const char q = s_[i_++];
      const auto end = s_.find(q, i_);
      if (end == std::string_view::npos) return fail("unterminated attribute"), std::nullopt;
      std::string value;
      if (!decode(i_, end, value)) return std::nullopt;
      if (!e.attrs.emplace(key, value).second) return fail("duplicate attribute " + key), std::nullopt;
      i_ = end + 1;
    }
    for (;;) {
      if (i_ >= s_.size()) return fail("unclosed <" + e.name + ">"), std::nullopt;
      if (starts("</")) {
        i_ += 2;
        const std::string closing = name();
        ws();
        if (closing != e.name) return fail("</" + closing + "> closes <" + e.name + ">"), std::nullopt;
        if (!starts(">")) return fail("expected '>'"), std::nullopt;
        ++i_;
        return e;
      }
      if (starts("<!--")) {
        if (!skip_until("-->")) return std::nullopt;
        continue;
      }
      if (starts("<![CDATA[") || starts("<!") || starts("<?")) return fail("unsupported markup"), std::nullopt;
      if (starts("<")) {
        auto child = element();
        if (!child) return std::nullopt;
        e.children.push_back(std::move(*child));
        continue;
      }
      const auto lt = s_.find('<', i_);
      const std::size_t end = lt == std::string_view::npos ? s_.size() : lt;
      if (!decode(i_, end, e.text)) return std::nullopt;
      i_ = end;
    }
  }

  std::string_view s_;
  std::size_t i_ = 0;
  std::string fail_;
};

inline Result parse(std::string_view s) { return Parser(s).run(); }

}  // namespace xml_mini
