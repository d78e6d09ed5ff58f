#include "harness/sim/egl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>

#include <cstdio>

#include "harness/base/errors.h"

namespace tgnav::harness {

namespace {
constexpr const char* kHint =
    " (install libegl1 libegl-mesa0 libgl1-mesa-dri, or set EGL_PLATFORM=surfaceless; "
    "scripts/setup.sh does the former)";

std::string eglErrorText() {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "0x%04x", static_cast<unsigned>(eglGetError()));
  return buf;
}
}  // namespace

EglContext::EglContext() {
  EGLDisplay dpy = EGL_NO_DISPLAY;
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display != nullptr) {
    dpy = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  }
  if (dpy == EGL_NO_DISPLAY) dpy = eglGetDisplay(EGL_DEFAULT_DISPLAY);
  EGLint major = 0;
  EGLint minor = 0;
  if (dpy == EGL_NO_DISPLAY || eglInitialize(dpy, &major, &minor) != EGL_TRUE) {
    throw InputError("EGL: no usable display, error " + eglErrorText() + kHint);
  }
  const EGLint config_attribs[] = {EGL_SURFACE_TYPE,
                                   EGL_PBUFFER_BIT,
                                   EGL_RED_SIZE,
                                   8,
                                   EGL_GREEN_SIZE,
                                   8,
                                   EGL_BLUE_SIZE,
                                   8,
                                   EGL_ALPHA_SIZE,
                                   8,
                                   EGL_DEPTH_SIZE,
                                   24,
                                   EGL_RENDERABLE_TYPE,
                                   EGL_OPENGL_BIT,
                                   EGL_NONE};
  EGLConfig config = nullptr;
  EGLint num_configs = 0;
  if (eglChooseConfig(dpy, config_attribs, &config, 1, &num_configs) != EGL_TRUE || num_configs < 1) {
    throw InputError("EGL: no RGBA8/depth24 OpenGL config, error " + eglErrorText() + kHint);
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
    throw InputError("EGL: desktop OpenGL API unavailable, error " + eglErrorText() + kHint);
  }
  EGLContext ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, nullptr);
  if (ctx == EGL_NO_CONTEXT) {
    throw InputError("EGL: cannot create an OpenGL context, error " + eglErrorText() + kHint);
  }
  display_ = dpy;
  context_ = ctx;
  makeCurrent();
}

EglContext::~EglContext() {
  // The display is shared by the whole process, so it is not terminated here.
  if (eglGetCurrentContext() == static_cast<EGLContext>(context_)) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
  eglDestroyContext(display_, static_cast<EGLContext>(context_));
}

bool EglContext::tryMakeCurrent() const noexcept {
  return eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, static_cast<EGLContext>(context_)) == EGL_TRUE;
}

void EglContext::makeCurrent() const {
  if (!tryMakeCurrent()) {
    throw InputError(
        "EGL: cannot make the context current (surfaceless contexts need "
        "EGL_KHR_surfaceless_context), error " +
        eglErrorText() + kHint);
  }
}

std::string EglContext::renderer() const {
  const auto* text = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  return text != nullptr ? text : "unknown";
}

}  // namespace tgnav::harness
