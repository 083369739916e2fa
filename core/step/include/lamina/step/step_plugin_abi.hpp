#pragma once
// What the CLI and the STEP module (core/step/plugin) must agree on to pass a TriangleSoup across
// the dlopen boundary: the project's version and the sizes of the types that cross it. Both
// sides compute it from the same headers; a module from another build says something else.
#include "lamina/core/error.hpp"
#include "lamina/core/triangle_soup.hpp"
#include "lamina/step/cad_reader.hpp"

#include <expected>
#include <string>

#ifndef LAMINA_VERSION
#error "LAMINA_VERSION must be defined (the project's version)"
#endif

namespace lamina {

inline const char* step_plugin_abi() {
  static const std::string abi = std::string("lamina-step ") + LAMINA_VERSION + " soup " +
                                 std::to_string(sizeof(TriangleSoup)) + " options " +
                                 std::to_string(sizeof(CadReadOptions)) + " result " +
                                 std::to_string(sizeof(std::expected<TriangleSoup, Error>));
  return abi.c_str();
}

}  // namespace lamina
