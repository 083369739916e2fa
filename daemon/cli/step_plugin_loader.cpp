// Opens liblamina_step.so once, checks that it was built with this program's interface, and
// keeps it open for the process's life (OpenCASCADE's singletons must outlive its last use).
#include "step_plugin_loader.hpp"

#include "own_path.hpp"

#include "lamina/step/step_plugin_abi.hpp"

#include <dlfcn.h>
#include <fmt/format.h>

#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>

namespace lamina::cli {

namespace {

using AbiFn = const char* (*)();
using ReadFn = void (*)(const char*, const CadReadOptions*, std::expected<TriangleSoup, Error>*);

struct Module {
  ReadFn read = nullptr;
  std::string error;  // why it is not usable
};

Module open_module() {
  const std::filesystem::path where = step_plugin_path();
  Module m;
  auto refuse = [&](const std::string& why) {
    m.error = fmt::format("the STEP/IGES reader {} {}: reinstall lamina, or export the part as STL or 3MF", where.string(), why);
    return m;
  };
  void* handle = dlopen(where.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* e = dlerror();
    return refuse(fmt::format("cannot be loaded ({})", e ? e : "no reason given"));
  }
  const auto abi = reinterpret_cast<AbiFn>(dlsym(handle, "lamina_step_plugin_abi"));
  const auto read = reinterpret_cast<ReadFn>(dlsym(handle, "lamina_step_read_cad_file"));
  if (!abi || !read) {
    ::dlclose(handle);
    return refuse("is not a Lamina STEP module");
  }
  if (std::strcmp(abi(), step_plugin_abi()) != 0) {
    const std::string other = abi();
    ::dlclose(handle);
    return refuse(fmt::format("is from another build ('{}', this program is '{}')", other, step_plugin_abi()));
  }
  m.read = read;
  return m;
}

}  // namespace

std::filesystem::path step_plugin_path() {
  if (const char* env = std::getenv("LAMINA_STEP_PLUGIN"); env && *env) return env;
  const auto self = own_program_path();
  const std::filesystem::path bin = self ? self->parent_path() : std::filesystem::current_path();
  return bin.parent_path() / "lib" / "lamina" / "liblamina_step.so";
}

std::expected<TriangleSoup, Error> read_cad_file_via_plugin(const std::filesystem::path& path,
                                                            const CadReadOptions& options) {
  static std::once_flag once;
  static Module module;
  std::call_once(once, [] { module = open_module(); });
  if (!module.read) return std::unexpected(Error{ErrorCode::unsupported, fmt::format("{}: {}", path.string(), module.error)});
  std::expected<TriangleSoup, Error> out = std::unexpected(Error{ErrorCode::io_error, "the STEP module returned nothing"});
  module.read(path.c_str(), &options, &out);
  return out;
}

}  // namespace lamina::cli
