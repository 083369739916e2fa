// The STEP/IGES reader as a module the CLI opens only when it reads such a file
// (daemon/cli/step_plugin_loader.cpp): linking OpenCASCADE's 80 libraries into `lamina` cost
// 0.1 s at every start, STL plans included. Two C entry points: the interface's fingerprint,
// which the loader compares with its own so a module from another build is refused, and the read.
#include "lamina/step/cad_reader.hpp"
#include "lamina/step/step_plugin_abi.hpp"

extern "C" __attribute__((visibility("default"))) const char* lamina_step_plugin_abi() {
  return lamina::step_plugin_abi();
}

extern "C" __attribute__((visibility("default"))) void lamina_step_read_cad_file(
    const char* path, const lamina::CadReadOptions* options, std::expected<lamina::TriangleSoup, lamina::Error>* out) {
  *out = lamina::read_cad_file(path, *options);
}
