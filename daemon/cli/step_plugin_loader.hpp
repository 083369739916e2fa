#pragma once
// The STEP/IGES reader, opened on first use from liblamina_step.so (core/step/plugin): `lamina`
// does not link OpenCASCADE, so reading an STL does not pay for loading it.
#include "lamina/core/error.hpp"
#include "lamina/core/triangle_soup.hpp"
#include "lamina/step/cad_reader.hpp"

#include <expected>
#include <filesystem>

namespace lamina::cli {

// Where the module is looked for: $LAMINA_STEP_PLUGIN if set, else lib/lamina/liblamina_step.so
// beside the program's bin/ (the build tree and an installed /usr are laid out alike).
std::filesystem::path step_plugin_path();

// read_cad_file through the module; an error names the module when it is missing, cannot be
// loaded, or comes from another build.
std::expected<TriangleSoup, Error> read_cad_file_via_plugin(const std::filesystem::path& path,
                                                            const CadReadOptions& options);

}  // namespace lamina::cli
