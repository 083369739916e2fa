#pragma once
// The machine file (config/machine.toml): kinematics, post, motion limits, cutting defaults, the jet,
// the feed model and nesting, read once and converted to core units (mm, s, rad, SI). Any key not
// known is an error naming the file, the line and the key.
#include "lamina/core/cam_settings.hpp"
#include "lamina/core/error.hpp"
#include "lamina/core/feed.hpp"
#include "lamina/core/kinematics.hpp"
#include "lamina/core/nest.hpp"
#include "lamina/core/post.hpp"
#include "lamina/core/toolpath.hpp"

#include <expected>
#include <string>
#include <string_view>

namespace lamina::cli {

// Errors: io_error (cannot read), parse_error ("FILE:LINE: what").
std::expected<MachineConfig, Error> read_machine_file(const std::string& path);
std::expected<MachineConfig, Error> parse_machine_toml(std::string_view text, const std::string& source_name);

// The folder of the default config files: $LAMINA_CONFIG_DIR, else the one this build was made from.
std::string default_config_dir();

}  // namespace lamina::cli
