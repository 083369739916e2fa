#pragma once
// Pieces of the post-processor shared between post.cpp, post_axes.cpp and post_dialects.cpp.
#include "lamina/core/error.hpp"
#include "lamina/core/kinematics.hpp"
#include "lamina/core/post.hpp"
#include "lamina/core/toolpath.hpp"

#include <cstddef>
#include <expected>
#include <numbers>
#include <string>
#include <vector>

namespace lamina::post_detail {

inline constexpr double deg_per_rad = 180.0 / std::numbers::pi;

// Lines are kept shorter than this (newline excluded): Grbl 1.1 reads at most 80 characters a
// line (protocol.h LINE_BUFFER_SIZE 80); grblHAL 256, LinuxCNC and Fanuc more.
inline constexpr std::size_t max_line_chars = 69;

// Machine axes at the end of every move: C unwound across the whole program (the nearest of the
// inverse's solutions to the previous C); with a limited C range, each contour shifted by the 2πk
// that keeps it in range, the shift changing ("rewind") only in the rapids between contours.
// Errors name the contour (or rapid move) that the head cannot reach.
std::expected<std::vector<AxisPose>, Error> plan_machine_axes(const SheetToolpath& toolpath,
                                                             const HeadKinematics& head);

// Poses as the controller will read them (post_rotary.cpp). Without RTCP, A and C are read
// rounded to angular_decimals, or held and shortened within one linear step at the sheet's far
// face (PostParams::hold_rotary_within_step), and X Y Z are computed from the angles written, so
// the tip lands where planned (to the linear rounding). RTCP poses are returned as they are.
std::vector<AxisPose> rounded_poses(const SheetToolpath& toolpath, const HeadKinematics& head, const PostParams& params,
                                    std::vector<AxisPose> poses);

// Dialect rules.
std::expected<void, Error> check_post_setup(const HeadKinematics& head, const PostParams& params);
bool keeps_decimal_point(PostDialect dialect);  // Fanuc: "X2." not "X2"
std::vector<std::string> program_start(const HeadKinematics& head, const PostParams& params);
std::vector<std::string> program_end(const HeadKinematics& head, const PostParams& params);
std::string dwell_line(double seconds, const PostParams& params);
std::string m_code_line(const std::string& codes);  // jet on/off text as one line, spaces removed

}  // namespace lamina::post_detail
