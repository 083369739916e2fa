// libFuzzer target: parse_3mf (the zip container, inflation and its bounds, relationships, the
// model XML, components and build items and their bound).
#include "fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  lamina::fuzz::check_reader([&](const lamina::MeshReadOptions& o) { return lamina::parse_3mf(bytes, lamina::fuzz::kName, o); },
                             {reinterpret_cast<const char*>(data), size});
  return 0;
}
