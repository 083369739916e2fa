// libFuzzer target: the ASCII STL parser itself (parse_stl would take most mutations for binary).
#include "fuzz_check.hpp"
#include "io/stl_detail.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  lamina::fuzz::check_reader(
      [&](const lamina::MeshReadOptions& o) {
        return lamina::io_detail::parse_stl_ascii(text, lamina::fuzz::kName, lamina::io_detail::FileQuote(o.quote_file_text));
      },
      text);
  return 0;
}
