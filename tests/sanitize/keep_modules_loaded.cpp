// Preloaded into every test process of the asan preset (LD_PRELOAD, set by
// cmake/resoctSanitizers.cmake): dlclose() does nothing, so no module is ever unloaded.
//
// Why: the Vulkan loader unloads the driver (Mesa's lavapipe, with LLVM) and the validation layer
// in vkDestroyInstance. Memory those modules keep in their own globals (lavapipe's once-per-process
// set-up, for one) is then referenced from nowhere, and LeakSanitizer, which looks for leaks at
// exit, reports it with frames in "<unknown module>". Kept loaded, that memory stays reachable from
// the modules' globals, as it is in any process that does not unload them; what a module really
// leaks is still reported, now with the module named (docs/testing.md "Sanitizers").
//
// Built without instrumentation: it is preloaded into uninstrumented processes too (python3, node,
// cmake), which have no sanitizer runtime to resolve instrumentation calls against.
extern "C" int dlclose(void* /*handle*/) {
  return 0;
}
