#pragma once
// The simulator's copy of the register map in docs/modbus-map.md (the single source both
// sides follow; a test reads the document and compares it with these numbers). Addresses are
// 0-based protocol addresses (coil 0 = 00001 in the old 5-digit notation).
#include <cstdint>

namespace lamina::sim::modbus_map {

// Coils (read/write bits).
inline constexpr int kCoilPumpEnable = 0;
inline constexpr int kCoilAbrasiveEnable = 1;
inline constexpr int kCoilJetOn = 2;
inline constexpr int kCoilAlarmReset = 3;  // write 1: clear the latched alarm; reads back 0
// The CNC's panel buttons, wired through the PLC (write 1 = press; the PLC sets it back to 0).
inline constexpr int kCoilCncFeedHold = 4;
inline constexpr int kCoilCncCycleStart = 5;
inline constexpr int kCoilCncReset = 6;
inline constexpr int kCoilCount = 7;
// Simulator-only fault coils (a real PLC has none): write 1 to inject, 0 to clear.
inline constexpr int kCoilSimEstop = 100;         // e-stop pressed
inline constexpr int kCoilSimDoorOpen = 101;      // door opened
inline constexpr int kCoilSimPressureDrop = 102;  // pump trips: pressure falls
inline constexpr int kCoilSimStall = 103;         // CNC stops draining its receive buffer
inline constexpr int kCoilSimEnd = 104;

// Discrete inputs (read-only bits).
inline constexpr int kInputEstopOk = 0;
inline constexpr int kInputDoorClosed = 1;
inline constexpr int kInputPumpReady = 2;
inline constexpr int kInputJetIsOn = 3;
inline constexpr int kInputAlarmLatched = 4;
inline constexpr int kInputCncJetRequest = 5;  // the CNC's jet M-code output as the PLC sees it
inline constexpr int kInputCount = 6;

// Input registers (read-only words).
inline constexpr int kInPressure = 0;          // 0.1 MPa
inline constexpr int kInAbrasiveFlow = 1;      // g/min
inline constexpr int kInHopperLevel = 2;       // 0.1 kg
inline constexpr int kInHeartbeatSeen = 3;     // counts heartbeat changes (wraps at 65536)
inline constexpr int kInMailboxAck = 4;        // sequence number of the last accepted block
inline constexpr int kInMailboxFree = 5;       // blocks the CNC queue can still take
inline constexpr int kInAlarmCode = 6;         // 0 none, see docs/modbus-map.md
inline constexpr int kInCncState = 7;          // 0 idle, 1 run, 2 hold pending, 3 hold, 4 alarm
inline constexpr int kInExecutedHigh = 8;      // executed blocks, high word
inline constexpr int kInExecutedLow = 9;       // executed blocks, low word
inline constexpr int kInPositionFirst = 10;    // X Y Z A C as int32 pairs (high, low), µm / mdeg
// The same pairs one by one (the daemon reads them by name): X Y Z in µm, A C in millidegrees.
inline constexpr int kInPositionXHigh = 10;
inline constexpr int kInPositionXLow = 11;
inline constexpr int kInPositionYHigh = 12;
inline constexpr int kInPositionYLow = 13;
inline constexpr int kInPositionZHigh = 14;
inline constexpr int kInPositionZLow = 15;
inline constexpr int kInPositionAHigh = 16;
inline constexpr int kInPositionALow = 17;
inline constexpr int kInPositionCHigh = 18;
inline constexpr int kInPositionCLow = 19;
inline constexpr int kInCount = 20;

// Holding registers (read/write words).
inline constexpr int kHoldPressureSetpoint = 0;  // 0.1 MPa
inline constexpr int kHoldHeartbeat = 1;         // the supervisor changes it every period
inline constexpr int kHoldAbrasiveSetpoint = 2;  // g/min
inline constexpr int kHoldMailboxSeq = 10;       // write last: a new value submits the block
inline constexpr int kHoldMailboxLength = 11;    // characters in the block (≤ 200)
inline constexpr int kHoldMailboxText = 12;      // 100 registers, 2 characters each, high byte first
inline constexpr int kMailboxTextRegisters = 100;
inline constexpr int kMailboxMaxChars = 200;
inline constexpr int kHoldCount = kHoldMailboxText + kMailboxTextRegisters;  // 112

// Alarm codes in kInAlarmCode.
inline constexpr std::uint16_t kAlarmNone = 0;
inline constexpr std::uint16_t kAlarmEstop = 1;
inline constexpr std::uint16_t kAlarmHeartbeat = 2;
inline constexpr std::uint16_t kAlarmMailboxOverrun = 3;  // a block written before the ack
inline constexpr std::uint16_t kAlarmMailboxBadBlock = 4; // length > 200 or the CNC refused it

}  // namespace lamina::sim::modbus_map
