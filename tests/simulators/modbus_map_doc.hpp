#pragma once
// docs/modbus-map.md read as tables, for the tests that check a side's register constants against
// it: the simulator's (test_modbus_map_doc.cpp) and the drivers' (test_plc_map_doc.cpp). Each side
// keeps its own copy of the numbers; this reads the one document both follow.
#include <gtest/gtest.h>

#include <cctype>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace lamina::modbus_doc {

// Which table a constant is documented in; the document's "## ..." headings name them.
enum class Table { coil, sim_coil, input, in, hold, size, alarm };

struct Constant {
  const char* name;
  int value;
  Table table;
};

inline std::string snake(const std::string& camel) {
  std::string out;
  for (char ch : camel) {
    if (std::isupper(static_cast<unsigned char>(ch))) {
      if (!out.empty()) out.push_back('_');
      out.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(ch))));
    } else {
      out.push_back(ch);
    }
  }
  return out;
}

// The naming rule at the top of docs/modbus-map.md.
inline std::string doc_name(const Constant& c) {
  std::string rest = std::string(c.name).substr(1);  // without k
  auto strip = [&](const std::string& prefix) {
    if (rest.rfind(prefix, 0) == 0) rest = rest.substr(prefix.size());
  };
  switch (c.table) {
    case Table::coil:
    case Table::sim_coil: strip("Coil"); break;
    case Table::input: strip("Input"); break;
    case Table::in: strip("In"); break;
    case Table::hold: strip("Hold"); break;
    case Table::alarm: strip("Alarm"); break;
    case Table::size: break;
  }
  return snake(rest);
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct DocRow {
  int value;
  int line;
};
using DocTables = std::map<Table, std::map<std::string, DocRow>>;

// Rows "| <number> | <name> | ..." under the headings that name a table.
inline DocTables parse_doc(const std::string& text) {
  const std::vector<std::pair<std::string, Table>> headings{
      {"## Coils", Table::coil},           {"## Simulator-only fault coils", Table::sim_coil},
      {"## Discrete inputs", Table::input}, {"## Input registers", Table::in},
      {"## Holding registers", Table::hold}, {"## Sizes and aliases", Table::size},
      {"## Alarm codes", Table::alarm}};
  const std::regex row(R"(^\|\s*(\d+)\s*\|\s*([a-z0-9_]+)\s*\|)");
  DocTables tables;
  Table current = Table::coil;
  bool in_table = false;  // (not std::optional: g++ 12 warns falsely about it here)
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  while (std::getline(lines, line)) {
    ++number;
    if (line.rfind("## ", 0) == 0) {
      in_table = false;
      for (const auto& [prefix, table] : headings)
        if (line.rfind(prefix, 0) == 0) {
          current = table;
          in_table = true;
        }
      continue;
    }
    std::smatch m;
    if (!in_table || !std::regex_search(line, m, row)) continue;
    auto [it, fresh] = tables[current].emplace(m[2].str(), DocRow{std::stoi(m[1].str()), number});
    EXPECT_TRUE(fresh) << "line " << number << ": " << m[2] << " is documented twice in one table";
  }
  return tables;
}

// Every `inline constexpr … kName =` of the header at `path` is in `constants`, and no other:
// a constant added to a side's map without being checked against the document fails.
inline void expect_header_constants_known(const std::string& path, const std::vector<Constant>& constants) {
  const std::string header = read_text(path);
  ASSERT_FALSE(header.empty()) << "cannot read " << path;
  const std::regex declaration(R"(inline\s+constexpr\s+[\w:]+\s+(k\w+)\s*=)");
  std::set<std::string> in_header, in_test;
  for (auto it = std::sregex_iterator(header.begin(), header.end(), declaration); it != std::sregex_iterator(); ++it)
    in_header.insert((*it)[1]);
  for (const Constant& c : constants) in_test.insert(c.name);
  EXPECT_EQ(in_header, in_test) << "a constant of " << path << " is not checked against docs/modbus-map.md";
}

}  // namespace lamina::modbus_doc
