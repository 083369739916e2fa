#pragma once
// Phase timings (the report's `timing_s`, the CLI's progress): wall seconds on the steady clock.
#include <chrono>

namespace lamina {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace lamina
