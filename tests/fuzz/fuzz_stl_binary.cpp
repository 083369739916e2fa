// libFuzzer target: parse_stl (binary STL, and whatever else the content probe makes of the bytes).
#include "fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  lamina::fuzz::check_reader([&](const lamina::MeshReadOptions& o) { return lamina::parse_stl(bytes, lamina::fuzz::kName, o); },
                             {reinterpret_cast<const char*>(data), size});
  return 0;
}
