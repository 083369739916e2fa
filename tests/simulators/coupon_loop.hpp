#pragma once
// The calibration loop's steps, shared by the tests that run it (test_coupon_loop.cpp,
// test_jet_loop.cpp): the commands run as a user runs them, lamina's coupon cut and "measured" on
// a lamina-sim machine with given jet_* keys, the readings filled into lamina's CSV by label, and
// the fit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>

#include <unistd.h>

namespace coupon_loop {

namespace fs = std::filesystem;

inline std::string run(const std::string& command) {
  std::string out;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  char buf[4096];
  while (pipe && std::fgets(buf, sizeof buf, pipe)) out += buf;
  const int status = pipe ? ::pclose(pipe) : -1;
  if (status != 0) out += "\n(exit status " + std::to_string(status) + ")";
  return out;
}

inline double number_after(const std::string& text, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(key + R"( = ([-0-9.e+]+))"))) return std::nan("");
  return std::stod(m[1]);
}

// The coupon cut and measured on a machine with these jet_* keys, fitted; the kerf file's text
// and the fit's output.
inline std::pair<std::string, std::string> calibrate_on(const std::string& name, const std::string& jet_keys) {
  // One folder per process: ctest runs the tests that calibrate the same machine side by side.
  const fs::path dir = fs::temp_directory_path() / ("lamina-coupon-loop-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string cli = LAMINA_CLI, sim = LAMINA_SIM, material = "'aluminium 6061-T6'";
  std::string out = run(cli + " calibrate coupon --material " + material + " --thickness 10 --out " + dir.string());
  EXPECT_TRUE(fs::exists(dir / "coupon.csv")) << out;
  std::ofstream(dir / "machine.toml") << "head_pivot_mm = 150\n" << jet_keys;
  out = run(sim + " --machine " + (dir / "machine.toml").string() + " --measure-coupon " + (dir / "coupon.nc").string() +
            " --sheet-thickness 10 --measure-seed 5 --measure-out " + (dir / "readings.csv").string());
  EXPECT_TRUE(out.empty()) << out;

  // The readings into Lamina's sheet, row by row by label, as a person fills it in.
  std::map<std::string, std::string> readings;
  std::ifstream r(dir / "readings.csv");
  for (std::string line; std::getline(r, line);)
    if (!line.starts_with("label,")) readings[line.substr(0, line.find(','))] = line.substr(line.find(',') + 1);
  std::ifstream sheet(dir / "coupon.csv");
  std::ostringstream filled;
  int rows = 0;
  for (std::string line; std::getline(sheet, line);) {
    if (line.empty() || line[0] == '#' || line.starts_with("label,")) {
      filled << line << "\n";
      continue;
    }
    const std::string label = line.substr(0, line.find(','));
    EXPECT_TRUE(readings.contains(label)) << label;
    filled << line.substr(0, line.size() - 3) << "," << readings[label] << "\n";  // the three empty cells
    ++rows;
  }
  EXPECT_EQ(rows, 10);
  std::ofstream(dir / "measured.csv") << filled.str();
  out = run(cli + " calibrate fit " + (dir / "measured.csv").string() + " --material " + material + " --kerf-file " +
            (dir / "kerf.toml").string());
  std::ifstream k(dir / "kerf.toml");
  std::string kerf{std::istreambuf_iterator<char>(k), std::istreambuf_iterator<char>()};
  fs::remove_all(dir);
  return {kerf, out};
}

}  // namespace coupon_loop
