// libFuzzer target: parse_obj (statements, indices, and the triangulation of polygons, large
// faces through the indexed clipper).
#include "fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  lamina::fuzz::check_reader([&](const lamina::MeshReadOptions& o) { return lamina::parse_obj(text, lamina::fuzz::kName, o); },
                             text);
  return 0;
}
