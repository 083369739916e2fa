#pragma once
// The drivers' copy of the cell PLC's register numbers (docs/modbus-map.md is the single
// source; the simulator keeps its own copy, so a misreading on one side cannot hide on the
// other). 0-based protocol addresses, as libmodbus takes them.
#include <cstdint>

namespace lamina::drivers::plc_map {

// Coils.
inline constexpr int kCoilPumpEnable = 0;
inline constexpr int kCoilAbrasiveEnable = 1;
inline constexpr int kCoilJetOn = 2;
inline constexpr int kCoilAlarmReset = 3;
inline constexpr int kCoilCncFeedHold = 4;    // push buttons: write 1, the PLC clears them
inline constexpr int kCoilCncCycleStart = 5;
inline constexpr int kCoilCncReset = 6;

// Discrete inputs (read together: 0…5).
inline constexpr int kInputEstopOk = 0;
inline constexpr int kInputDoorClosed = 1;
inline constexpr int kInputPumpReady = 2;
inline constexpr int kInputJetIsOn = 3;
inline constexpr int kInputAlarmLatched = 4;
inline constexpr int kInputCncJetRequest = 5;  // the CNC's own jet output (its M-code), wired in
inline constexpr int kInputCount = 6;

// Input registers (read together: 0…19).
inline constexpr int kInPressure = 0;        // 0.1 MPa
inline constexpr int kInAbrasiveFlow = 1;    // g/min
inline constexpr int kInMailboxAck = 4;
inline constexpr int kInMailboxFree = 5;
inline constexpr int kInAlarmCode = 6;
inline constexpr int kInCncState = 7;        // 0 idle, 1 run, 2 hold pending, 3 hold, 4 alarm
inline constexpr int kInExecutedHigh = 8;    // uint32, high word first
inline constexpr int kInPositionFirst = 10;  // X Y Z (µm) A C (millidegree), int32 pairs
inline constexpr int kInCount = 20;

// Holding registers.
inline constexpr int kHoldPressureSetpoint = 0;  // 0.1 MPa
inline constexpr int kHoldHeartbeat = 1;
inline constexpr int kHoldAbrasiveSetpoint = 2;  // g/min
inline constexpr int kHoldMailboxSeq = 10;       // seq, length, text: one FC16 from here
inline constexpr int kMailboxTextRegisters = 100;
inline constexpr int kMailboxMaxChars = 200;

// Alarm codes.
inline constexpr std::uint16_t kAlarmEstop = 1;
inline constexpr std::uint16_t kAlarmHeartbeat = 2;
inline constexpr std::uint16_t kAlarmMailboxOverrun = 3;
inline constexpr std::uint16_t kAlarmMailboxBadBlock = 4;

inline const char* alarm_name(int code) {
  switch (code) {
    case 0: return "none";
    case kAlarmEstop: return "e-stop";
    case kAlarmHeartbeat: return "heartbeat watchdog";
    case kAlarmMailboxOverrun: return "mailbox overrun";
    case kAlarmMailboxBadBlock: return "mailbox bad block";
  }
  return "unknown alarm";
}

}  // namespace lamina::drivers::plc_map
