// The simulator's own G-code parser: lines our posts emit, and every error it reports.
#include <gtest/gtest.h>

#include <string>

#include "gcode_block.hpp"

namespace lamina::sim {
namespace {

ParseResult parse(std::string_view line, ParseParams params = {}) { return parse_block(line, params); }

GrblStatus status(std::string_view line, ParseParams params = {}) { return parse(line, params).status; }

TEST(GcodeBlock, InverseTimeFiveAxisLineFromThePost) {
  const auto r = parse("G93G1X12.5Y3A-20.1C181.2F612.3");
  ASSERT_EQ(r.status, GrblStatus::ok);
  const Block& b = r.block;
  EXPECT_EQ(b.motion, MotionMode::linear);
  EXPECT_EQ(b.set_inverse_time, std::optional<bool>(true));
  EXPECT_DOUBLE_EQ(*b.axis_words[0], 12.5);
  EXPECT_DOUBLE_EQ(*b.axis_words[1], 3);
  EXPECT_FALSE(b.axis_words[2].has_value());  // no Z word
  EXPECT_DOUBLE_EQ(*b.axis_words[3], -20.1);
  EXPECT_DOUBLE_EQ(*b.axis_words[4], 181.2);
  EXPECT_DOUBLE_EQ(*b.feed_word, 612.3);
  EXPECT_EQ(b.source, "G93G1X12.5Y3A-20.1C181.2F612.3");
  EXPECT_FALSE(b.comment_only);
}

TEST(GcodeBlock, CommentLineWithGcodeInsideIsCommentOnly) {
  // The words inside the parentheses must not be read as G1 / G94 / F600.
  const auto r = parse("(CONTOUR 3 L16-1 OUTLINE 2 PASS 1 G1 G94 F600)");
  ASSERT_EQ(r.status, GrblStatus::ok);
  EXPECT_TRUE(r.block.comment_only);
  EXPECT_EQ(r.block.motion, MotionMode::none);
  EXPECT_FALSE(r.block.feed_word.has_value());
  EXPECT_FALSE(r.block.set_inverse_time.has_value());
  EXPECT_TRUE(parse("").block.comment_only);
  EXPECT_TRUE(parse("  ; just a note G0 X5").block.comment_only);
}

TEST(GcodeBlock, LineNumberSpacesAndLowerCase) {
  const auto r = parse("N10 G0 Z5");
  ASSERT_EQ(r.status, GrblStatus::ok);
  EXPECT_EQ(r.block.line_number, std::optional<std::int64_t>(10));
  EXPECT_EQ(r.block.motion, MotionMode::rapid);
  EXPECT_DOUBLE_EQ(*r.block.axis_words[2], 5);
  // Spaces inside a word are ignored as Grbl strips them; letters are case-insensitive.
  const auto lower = parse("g1 x 1 0 (mid) y-.5 f 300 ; tail");
  ASSERT_EQ(lower.status, GrblStatus::ok);
  EXPECT_DOUBLE_EQ(*lower.block.axis_words[0], 10);
  EXPECT_DOUBLE_EQ(*lower.block.axis_words[1], -0.5);
  EXPECT_DOUBLE_EQ(*lower.block.feed_word, 300);
}

TEST(GcodeBlock, JetMcodesFollowTheConfiguration) {
  EXPECT_EQ(parse("M3").block.jet_on, std::optional<bool>(true));
  EXPECT_EQ(parse("M5").block.jet_on, std::optional<bool>(false));
  ParseParams custom;
  custom.jet_on_mcodes = {62};
  custom.jet_off_mcodes = {63};
  EXPECT_EQ(parse("M62", custom).block.jet_on, std::optional<bool>(true));
  EXPECT_EQ(parse("M63", custom).block.jet_on, std::optional<bool>(false));
  // M3 stays grblHAL's spindle command (accepted), but it is not this machine's jet.
  EXPECT_EQ(parse("M3", custom).block.jet_on, std::nullopt);
  EXPECT_EQ(parse("M3", custom).block.spindle, std::optional<SpindleCommand>(SpindleCommand::cw));
  EXPECT_EQ(parse("M4").block.jet_on, std::optional<bool>(true));  // by default M4 is the jet too
  EXPECT_EQ(parse("M8").block.coolant, std::optional<CoolantCommand>(CoolantCommand::flood));
  EXPECT_EQ(status("M62"), GrblStatus::unsupported_command);  // not configured by default
  EXPECT_TRUE(parse("M2").block.program_end);
  EXPECT_TRUE(parse("M30").block.program_end);
}

TEST(GcodeBlock, DwellPercentAndModalWords) {
  const auto dwell = parse("G4P0.5");
  ASSERT_EQ(dwell.status, GrblStatus::ok);
  EXPECT_EQ(dwell.block.motion, MotionMode::dwell);
  EXPECT_DOUBLE_EQ(*dwell.block.dwell_s, 0.5);
  EXPECT_TRUE(parse("%").block.percent);
  EXPECT_TRUE(parse(" % ").block.percent);
  EXPECT_FALSE(parse("G0X1").block.percent);
  const auto modal = parse("G21G90G94G17G40G49");
  ASSERT_EQ(modal.status, GrblStatus::ok);
  EXPECT_EQ(modal.block.set_inches, std::optional<bool>(false));
  EXPECT_EQ(modal.block.set_relative, std::optional<bool>(false));
  EXPECT_EQ(modal.block.set_inverse_time, std::optional<bool>(false));
  EXPECT_EQ(modal.block.motion, MotionMode::none);
  const auto g20 = parse("G20G91");
  EXPECT_EQ(g20.block.set_inches, std::optional<bool>(true));
  EXPECT_EQ(g20.block.set_relative, std::optional<bool>(true));
  const auto arc = parse("G2X10Y0I5J0");
  ASSERT_EQ(arc.status, GrblStatus::ok);
  EXPECT_EQ(arc.block.motion, MotionMode::arc_cw);
  EXPECT_DOUBLE_EQ(*arc.block.i_mm, 5);
  EXPECT_EQ(parse("G3X1R2").block.motion, MotionMode::arc_ccw);
}

// grblHAL keeps a letter without an axis as a parameter word; the executor answers
// unused_words (36) for it after its other checks (Machine tests cover the answer).
TEST(GcodeBlock, LetterWithoutAnAxisIsAnUnusedValueWord) {
  EXPECT_EQ(status("G1B10F100"), GrblStatus::ok);
  EXPECT_TRUE(parse("G1 B10 F100").block.unused_word);
  EXPECT_TRUE(parse("E5").block.unused_word);
  EXPECT_TRUE(parse("G1 U1").block.unused_word);
  EXPECT_FALSE(parse("G1 X1 A2 C3").block.unused_word);
  EXPECT_EQ(status("G1 Bx"), GrblStatus::bad_number_format);  // the number is read first
  EXPECT_EQ(status("G38"), GrblStatus::unsupported_command);
  EXPECT_EQ(status("T1 S1000"), GrblStatus::ok);  // accepted and ignored
}

TEST(GcodeBlock, BadNumbers) {
  EXPECT_EQ(status("X1.2.3"), GrblStatus::bad_number_format);
  EXPECT_EQ(status("X-"), GrblStatus::bad_number_format);
  EXPECT_EQ(status("Xabc"), GrblStatus::bad_number_format);
  EXPECT_EQ(status("G1X--1"), GrblStatus::bad_number_format);
  EXPECT_EQ(status("G1X."), GrblStatus::bad_number_format);
  EXPECT_EQ(status("G1X.5"), GrblStatus::ok);
  EXPECT_EQ(status("G1X5."), GrblStatus::ok);
}

TEST(GcodeBlock, StructuralErrors) {
  EXPECT_EQ(status("G1X1X2"), GrblStatus::word_repeated);
  EXPECT_EQ(status("G1F100F200"), GrblStatus::word_repeated);
  EXPECT_EQ(status("G0G1X1"), GrblStatus::modal_group_violation);
  EXPECT_EQ(status("G20G21"), GrblStatus::modal_group_violation);
  EXPECT_EQ(status("M3M5"), GrblStatus::modal_group_violation);
  EXPECT_EQ(status("G4P1X3"), GrblStatus::modal_group_violation);
  EXPECT_EQ(status("G1.5X1"), GrblStatus::command_value_not_integer);
  EXPECT_EQ(status("M3.2"), GrblStatus::command_value_not_integer);
  EXPECT_EQ(status("G4"), GrblStatus::value_word_missing);
  EXPECT_EQ(status("G1X1P2"), GrblStatus::unused_words);
  EXPECT_EQ(status("(unterminated G1 X1"), GrblStatus::expected_command_letter);
  EXPECT_EQ(status("1X2"), GrblStatus::expected_command_letter);
  EXPECT_EQ(status("G1F-5"), GrblStatus::negative_value);
}

TEST(GcodeBlock, LineNumberRange) {
  EXPECT_EQ(status("N-1G0X1"), GrblStatus::invalid_line_number);
  EXPECT_EQ(status("N10000001"), GrblStatus::invalid_line_number);  // Grbl max is 10000000
  EXPECT_EQ(status("N10000000"), GrblStatus::ok);
  EXPECT_EQ(status("N1.5"), GrblStatus::invalid_line_number);
}

TEST(GcodeBlock, LineLongerThanTheBufferOverflows) {
  ParseParams params;
  params.max_line_chars = 20;
  const std::string fits = "G1X1" + std::string(16, ' ');  // exactly 20 characters
  EXPECT_EQ(status(fits, params), GrblStatus::ok);
  EXPECT_EQ(status(fits + " ", params), GrblStatus::overflow);
  // Default buffer 256: `G0X1` (4) + `(` + 250 c + `)` = 256 fits; one more c does not.
  EXPECT_EQ(status("G0X1(" + std::string(250, 'c') + ")"), GrblStatus::ok);
  EXPECT_EQ(status("G0X1(" + std::string(251, 'c') + ")"), GrblStatus::overflow);
}

}  // namespace
}  // namespace lamina::sim

namespace lamina::sim {
namespace {

TEST(GcodeBlock, FanucDialectReadsProgramNumbersAndDwellInMilliseconds) {
  ParseParams fanuc;
  fanuc.accept_program_number = true;
  fanuc.dwell_p_unit_s = 0.001;
  EXPECT_EQ(parse_block("O1000(KNOB.STL SHEET 1)", fanuc).status, GrblStatus::ok);
  EXPECT_EQ(parse_block("O1000", {}).status, GrblStatus::unsupported_command) << "Grbl has no O word";
  EXPECT_EQ(parse_block("O10.5", fanuc).status, GrblStatus::command_value_not_integer);
  const auto dwell = parse_block("G4P1000", fanuc);
  ASSERT_EQ(dwell.status, GrblStatus::ok);
  EXPECT_DOUBLE_EQ(*dwell.block.dwell_s, 1.0) << "P1000 is one second on a Fanuc";
  EXPECT_DOUBLE_EQ(*parse_block("G4P1.5", {}).block.dwell_s, 1.5) << "and P1.5 is 1.5 s on Grbl";
}

}  // namespace
}  // namespace lamina::sim
