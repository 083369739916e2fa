#pragma once
// Mesh readers (the edge of the pipeline where files are read).
#include "lamina/core/error.hpp"
#include "lamina/core/triangle_soup.hpp"

#include <cstddef>
#include <expected>
#include <filesystem>
#include <span>
#include <string_view>

namespace lamina {

// Parse an STL held in memory. Binary is recognised by its size (84 + 50·n bytes, with trailing
// padding noted), not by a leading "solid": several real binary files start their header with it.
std::expected<TriangleSoup, Error> parse_stl(std::span<const std::byte> bytes, std::string_view name);

// Parse Wavefront OBJ text; polygons are triangulated (ear clipping in their best-fit plane).
std::expected<TriangleSoup, Error> parse_obj(std::string_view text, std::string_view name);

// Parse a 3MF package (zip) held in memory: every build item's triangles, transformed. Needs zlib
// at build time; without it the result is Error unsupported.
std::expected<TriangleSoup, Error> parse_3mf(std::span<const std::byte> bytes, std::string_view name);

// Read a mesh file; the format comes from the content (STL) or the extension (.obj, .3mf).
std::expected<TriangleSoup, Error> read_mesh_file(const std::filesystem::path& path);

}  // namespace lamina
