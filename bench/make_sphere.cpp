// make_sphere OUT.stl [--segments N] [--rings N] [--radius R] [--centre-z Z]
//
// Writes a binary-STL UV sphere for benchmarks: by default radius 50 mm, 1000 meridians and
// 501 latitude bands = 2 * 1000 * 500 = 1,000,000 triangles, centred at (0, 0, 50) so it sits on
// the build plate (z = 0 … 100). CuraEngine slices the file's own z (it does not drop the
// mesh onto the plate unless center_object is set, and slices nothing below z = 0); it only
// shifts x and y by half the bed. The mesh comes from tests/support/shapes.hpp, so its exact
// faceted volume and section areas are known (printed here).
#include "shapes.hpp"

#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

namespace {

[[noreturn]] void usage(const char* why) {
  std::fprintf(stderr,
               "make_sphere: %s\n"
               "usage: make_sphere OUT.stl [--segments N] [--rings N] [--radius R] [--centre-z Z]\n"
               "  defaults: --segments 1000 --rings 501 --radius 50 --centre-z <radius>\n"
               "  triangles = 2 * segments * (rings - 1)\n",
               why);
  std::exit(2);
}

template <class T>
T parse(std::string_view flag, const char* text) {
  T v{};
  const std::string_view s(text);
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size())
    usage((std::string("bad value for ") + std::string(flag) + ": " + text).c_str());
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path out;
  int segments = 1000, rings = 501;
  double radius = 50.0;
  double centre_z = -1.0;
  bool centre_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a(argv[i]);
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) usage((std::string(a) + " needs a value").c_str());
      return argv[++i];
    };
    if (a == "--segments") segments = parse<int>(a, value());
    else if (a == "--rings") rings = parse<int>(a, value());
    else if (a == "--radius") radius = parse<double>(a, value());
    else if (a == "--centre-z" || a == "--center-z") centre_z = parse<double>(a, value()), centre_given = true;
    else if (a == "-h" || a == "--help") usage("writes a UV-sphere binary STL");
    else if (!a.empty() && a[0] == '-') usage((std::string("unknown option ") + std::string(a)).c_str());
    else if (out.empty()) out = a;
    else usage("more than one output path");
  }
  if (out.empty()) usage("no output path");
  if (!centre_given) centre_z = radius;

  try {
    const auto soup = lamina::test::translated(lamina::test::uv_sphere(radius, segments, rings),
                                               {0.0f, 0.0f, static_cast<float>(centre_z)});
    lamina::test::write_binary_stl(soup, out);
    std::printf("%s: %zu triangles, radius %g mm, centre z %g mm (z %g … %g), %d segments x %d rings,"
                " faceted volume %.3f mm^3, %ju bytes\n",
                out.string().c_str(), soup.triangle_count(), radius, centre_z, centre_z - radius,
                centre_z + radius, segments, rings,
                lamina::test::uv_sphere_volume(radius, segments, rings),
                static_cast<std::uintmax_t>(std::filesystem::file_size(out)));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_sphere: %s\n", e.what());
    return 1;
  }
  return 0;
}
