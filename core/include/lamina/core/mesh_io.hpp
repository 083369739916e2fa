#pragma once
// Mesh readers (the edge of the pipeline where files are read).
#include "lamina/core/error.hpp"
#include "lamina/core/triangle_soup.hpp"

#include <cstddef>
#include <cstdint>
#include <expected>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

namespace lamina {

// What a reader may say about a file, and how much work a file may ask of it. The defaults suit
// a person reading their own files; the limits are far above any real part (see each).
struct MeshReadOptions {
  // Quote the file's own bytes in errors and notes: offending tokens, solid names, 3MF units,
  // transforms and object ids, zip entry names, stored indices and sizes. Off for a file someone
  // else named (laminad plans for network clients, and a message must not become a way to read
  // any file the daemon can): every message still says where (file, line, byte offset, entry
  // number) and what was expected, but describes the bytes ("a token of 7 bytes") instead.
  bool quote_file_text = true;

  // 3MF: the most triangles the build may expand to (components within components, times build
  // items), counted before any is made. 10^8 triangles are 3.6 GB of corners and ten times the
  // largest parts we plan (a 10^7-triangle scan); nested components can multiply a 600-byte file
  // to 10^12.
  std::uint64_t max_triangles = 100'000'000;

  // 3MF: the most bytes one zip entry (the model part, the relationships) may inflate to: 2 GiB
  // of model XML is ~3·10^7 triangles. Inflation stops at the bound; nothing is allocated for a
  // declared size beyond it.
  std::uint64_t max_inflated_bytes = std::uint64_t{2} << 30;
  // ... and the most it may expand on its compressed size once above `inflate_ratio_from_bytes`.
  // Mesh XML deflates 5-20:1 (8.5:1 for a 160k-triangle sphere, 10:1 for an integer grid); only
  // repeated identical text reaches deflate's 1032:1, which turns a 1.4 MB file into 1.5 GB.
  // Small entries are exempt: whatever their ratio, they cannot cost much.
  std::uint32_t max_inflate_ratio = 100;
  std::uint64_t inflate_ratio_from_bytes = std::uint64_t{16} << 20;
};

// Parse an STL held in memory. Binary is recognised by its size (84 + 50·n bytes, with trailing
// padding noted), not by a leading "solid": several real binary files start their header with it.
std::expected<TriangleSoup, Error> parse_stl(std::span<const std::byte> bytes, std::string_view name,
                                             const MeshReadOptions& options = {});

// Parse Wavefront OBJ text; polygons are triangulated (ear clipping in their best-fit plane).
std::expected<TriangleSoup, Error> parse_obj(std::string_view text, std::string_view name,
                                             const MeshReadOptions& options = {});

// Parse a 3MF package (zip) held in memory: every build item's triangles, transformed. Needs zlib
// at build time; without it the result is Error unsupported.
std::expected<TriangleSoup, Error> parse_3mf(std::span<const std::byte> bytes, std::string_view name,
                                             const MeshReadOptions& options = {});

// The file's extension in lower case, with its dot (".step"); "" when it has none.
std::string lower_extension(const std::filesystem::path& path);
// .step .stp .iges .igs: a B-rep file, read by lamina_step (lamina/step/cad_reader.hpp), not here.
bool is_cad_path(const std::filesystem::path& path);

// Read a mesh file; the format comes from the content (STL) or the extension (.obj, .3mf).
std::expected<TriangleSoup, Error> read_mesh_file(const std::filesystem::path& path,
                                                  const MeshReadOptions& options = {});

}  // namespace lamina
