// A STEP module as another build would have made it: the right entry points, another interface
// fingerprint. `lamina` must refuse it rather than pass a TriangleSoup of another layout.
extern "C" __attribute__((visibility("default"))) const char* lamina_step_plugin_abi() {
  return "lamina-step 0.0.0 soup 1 options 1 result 1";
}

extern "C" __attribute__((visibility("default"))) void lamina_step_read_cad_file(const char*, const void*, void*) {
  __builtin_trap();  // never called: the fingerprint is checked first
}
