// LeakSanitizer suppressions for the GL stack (CI's ASan stage runs these suites): Mesa's EGL,
// llvmpipe and LLVM keep process-lifetime allocations that eglTerminate does not free. Only
// leaks whose stacks run through those libraries are suppressed; ours are still reported.
// An ordinary build never calls this hook.
extern "C" const char* __lsan_default_suppressions();
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libEGL_mesa\n"
         "leak:libEGL.so\n"
         "leak:libGLdispatch\n"
         "leak:libglapi\n"
         "leak:libgallium\n"
         "leak:swrast_dri\n"
         "leak:libLLVM\n"
         "leak:libGLX\n"
         "leak:libglfw\n";
}
