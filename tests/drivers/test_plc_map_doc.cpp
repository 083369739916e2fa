// The drivers' register numbers (drivers/src/plc_map.hpp) against docs/modbus-map.md, as the
// simulator's are checked (issue 18): each constant is documented with its value, and the test
// knows every constant of the header. The drivers need only part of the map (no simulator-only
// fault coils), so the check runs one way: from the header to the document.
#include <gtest/gtest.h>

#include "modbus_map_doc.hpp"
#include "plc_map.hpp"

namespace lamina::drivers {
namespace {
namespace pm = plc_map;
using namespace modbus_doc;

#define C(name, table) Constant{#name, pm::name, Table::table}
const std::vector<Constant> kConstants{
    C(kCoilPumpEnable, coil), C(kCoilAbrasiveEnable, coil), C(kCoilJetOn, coil), C(kCoilAlarmReset, coil),
    C(kCoilCncFeedHold, coil), C(kCoilCncCycleStart, coil), C(kCoilCncReset, coil),
    C(kInputEstopOk, input), C(kInputDoorClosed, input), C(kInputPumpReady, input), C(kInputJetIsOn, input),
    C(kInputAlarmLatched, input), C(kInputCncJetRequest, input), C(kInputCount, size),
    C(kInPressure, in), C(kInAbrasiveFlow, in), C(kInMailboxAck, in), C(kInMailboxFree, in), C(kInAlarmCode, in),
    C(kInCncState, in), C(kInExecutedHigh, in), C(kInPositionFirst, size), C(kInCount, size),
    C(kHoldPressureSetpoint, hold), C(kHoldHeartbeat, hold), C(kHoldAbrasiveSetpoint, hold),
    C(kHoldMailboxSeq, hold), C(kMailboxTextRegisters, size), C(kMailboxMaxChars, size),
    C(kAlarmEstop, alarm), C(kAlarmHeartbeat, alarm), C(kAlarmMailboxOverrun, alarm),
    C(kAlarmMailboxBadBlock, alarm),
};
#undef C

const std::string kDocPath = std::string(LAMINA_DOCS_DIR) + "/modbus-map.md";
const std::string kHeaderPath = std::string(LAMINA_DOCS_DIR) + "/../drivers/src/plc_map.hpp";

TEST(PlcMapDoc, EveryDriversConstantIsDocumentedWithItsValue) {
  const std::string text = read_text(kDocPath);
  ASSERT_FALSE(text.empty()) << "cannot read " << kDocPath;
  const DocTables tables = parse_doc(text);
  for (const Constant& c : kConstants) {
    const auto table = tables.find(c.table);
    ASSERT_NE(table, tables.end()) << "no table for " << c.name;
    const auto row = table->second.find(doc_name(c));
    if (row == table->second.end()) {
      ADD_FAILURE() << c.name << " is not documented (expected a row `| " << c.value << " | " << doc_name(c) << " |`)";
      continue;
    }
    EXPECT_EQ(row->second.value, c.value) << kDocPath << ":" << row->second.line << ": " << doc_name(c) << " is "
                                          << row->second.value << " in the document but plc_map::" << c.name
                                          << " = " << c.value;
  }
}

TEST(PlcMapDoc, TheTestKnowsEveryConstantOfTheHeader) { expect_header_constants_known(kHeaderPath, kConstants); }

}  // namespace
}  // namespace lamina::drivers
