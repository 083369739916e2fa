// docs/modbus-map.md is the register map both sides follow; modbus_map.hpp is the simulator's
// copy. This reads the document's tables and checks them against the constants, both ways.
#include <gtest/gtest.h>

#include <cctype>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "modbus_map.hpp"
#include "modbus_map_doc.hpp"

namespace lamina::sim {
namespace {
namespace mm = modbus_map;

using namespace modbus_doc;

#define C(name, table) Constant{#name, mm::name, Table::table}
// Every constant of modbus_map.hpp (the test below checks this list against the header's text,
// so a constant added there without being added here, and documented, fails).
const std::vector<Constant> kConstants{
    C(kCoilPumpEnable, coil), C(kCoilAbrasiveEnable, coil), C(kCoilJetOn, coil), C(kCoilAlarmReset, coil),
    C(kCoilCncFeedHold, coil), C(kCoilCncCycleStart, coil), C(kCoilCncReset, coil),
    C(kCoilCount, size),
    C(kCoilSimEstop, sim_coil), C(kCoilSimDoorOpen, sim_coil), C(kCoilSimPressureDrop, sim_coil),
    C(kCoilSimStall, sim_coil), C(kCoilSimEnd, size),
    C(kInputEstopOk, input), C(kInputDoorClosed, input), C(kInputPumpReady, input), C(kInputJetIsOn, input),
    C(kInputAlarmLatched, input), C(kInputCncJetRequest, input), C(kInputCount, size),
    C(kInPressure, in), C(kInAbrasiveFlow, in), C(kInHopperLevel, in), C(kInHeartbeatSeen, in),
    C(kInMailboxAck, in), C(kInMailboxFree, in), C(kInAlarmCode, in), C(kInCncState, in),
    C(kInExecutedHigh, in), C(kInExecutedLow, in), C(kInPositionFirst, size),
    C(kInPositionXHigh, in), C(kInPositionXLow, in), C(kInPositionYHigh, in), C(kInPositionYLow, in),
    C(kInPositionZHigh, in), C(kInPositionZLow, in), C(kInPositionAHigh, in), C(kInPositionALow, in),
    C(kInPositionCHigh, in), C(kInPositionCLow, in), C(kInCount, size),
    C(kHoldPressureSetpoint, hold), C(kHoldHeartbeat, hold), C(kHoldAbrasiveSetpoint, hold),
    C(kHoldMailboxSeq, hold), C(kHoldMailboxLength, hold), C(kHoldMailboxText, hold),
    C(kMailboxTextRegisters, size), C(kMailboxMaxChars, size), C(kHoldCount, size),
    C(kAlarmNone, alarm), C(kAlarmEstop, alarm), C(kAlarmHeartbeat, alarm), C(kAlarmMailboxOverrun, alarm),
    C(kAlarmMailboxBadBlock, alarm),
};
#undef C

const std::string kDocPath = std::string(LAMINA_DOCS_DIR) + "/modbus-map.md";
const std::string kHeaderPath = std::string(LAMINA_DOCS_DIR) + "/../simulators/src/modbus_map.hpp";

TEST(ModbusMapDoc, EveryConstantIsDocumentedWithItsValue) {
  const std::string text = read_text(kDocPath);
  ASSERT_FALSE(text.empty()) << "cannot read " << kDocPath;
  const DocTables tables = parse_doc(text);
  for (const auto& c : kConstants) {
    const std::string name = doc_name(c);
    const auto table = tables.find(c.table);
    ASSERT_NE(table, tables.end()) << "no table for " << c.name << " in " << kDocPath;
    const auto row = table->second.find(name);
    if (row == table->second.end()) {
      ADD_FAILURE() << c.name << " is not documented (expected a row `| " << c.value << " | " << name << " |`)";
      continue;
    }
    EXPECT_EQ(row->second.value, c.value)
        << kDocPath << ":" << row->second.line << ": " << name << " is " << row->second.value
        << " in the document but " << c.name << " = " << c.value;
  }
}

TEST(ModbusMapDoc, EveryDocumentedRowIsAConstant) {
  const DocTables tables = parse_doc(read_text(kDocPath));
  std::map<Table, std::set<std::string>> known;
  for (const auto& c : kConstants) known[c.table].insert(doc_name(c));
  std::size_t rows = 0;
  for (const auto& [table, rows_of_table] : tables)
    for (const auto& [name, row] : rows_of_table) {
      ++rows;
      EXPECT_TRUE(known[table].contains(name))
          << kDocPath << ":" << row.line << ": " << name << " has no constant in modbus_map.hpp";
    }
  EXPECT_EQ(rows, kConstants.size());
}

TEST(ModbusMapDoc, AddressesInOneAreaAreDistinct) {
  const DocTables tables = parse_doc(read_text(kDocPath));
  for (Table t : {Table::coil, Table::sim_coil, Table::input, Table::in, Table::hold, Table::alarm}) {
    std::map<int, std::string> by_address;
    const auto it = tables.find(t);
    if (it == tables.end()) continue;
    for (const auto& [name, row] : it->second) {
      auto [prev, fresh] = by_address.emplace(row.value, name);
      EXPECT_TRUE(fresh) << name << " and " << prev->second << " share address " << row.value;
    }
  }
}

TEST(ModbusMapDoc, TheTestKnowsEveryConstantOfTheHeader) { expect_header_constants_known(kHeaderPath, kConstants); }

}  // namespace
}  // namespace lamina::sim
