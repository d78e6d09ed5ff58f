#pragma once
// Headless OpenGL through EGL on Mesa's surfaceless platform (no display, no window, no GPU
// needed: llvmpipe renders on the CPU). MuJoCo renders into its own offscreen framebuffer, so
// the context needs no surface. An OpenGL context is current on one thread at a time: call
// makeCurrent() on the thread that renders.
#include <string>

namespace tgnav::harness {

class EglContext {
 public:
  // Throws InputError saying what to install or set when no EGL display or context is found.
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;
  EglContext(EglContext&&) = delete;
  EglContext& operator=(EglContext&&) = delete;

  void makeCurrent() const;
  // makeCurrent() that reports failure instead of throwing (for destructors).
  bool tryMakeCurrent() const noexcept;
  // GL_RENDERER of the current context, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
  std::string renderer() const;

 private:
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
};

}  // namespace tgnav::harness
