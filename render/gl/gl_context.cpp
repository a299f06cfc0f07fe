// Headless EGL context creation (see gl_context.h).
#include "lucent/render/gl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "gl_api.h"
#include "lucent/core/error.h"

namespace lucent::render {

struct GlContext::Egl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  std::string platform;
};

namespace {

std::string egl_error_name(EGLint e) {
  switch (e) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    default: {
      char buf[32];
      std::snprintf(buf, sizeof buf, "EGL error 0x%x", unsigned(e));
      return buf;
    }
  }
}

bool has_extension(const char* list, const char* name) {
  if (list == nullptr) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n) {
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  }
  return false;
}

void APIENTRY debug_callback(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                             const GLchar* message, const void*) {
  (void)source;
  (void)length;
  if (severity == GL_DEBUG_SEVERITY_NOTIFICATION) return;
  const char* kind = type == GL_DEBUG_TYPE_ERROR                 ? "error"
                     : type == GL_DEBUG_TYPE_PERFORMANCE         ? "performance"
                     : type == GL_DEBUG_TYPE_DEPRECATED_BEHAVIOR ? "deprecated"
                     : type == GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR  ? "undefined behaviour"
                                                                 : "note";
  std::fprintf(stderr, "lucent: GL %s (id %u): %s\n", kind, id, message);
}

// A display that initialises, for each way of finding one in turn; appends why each failed.
std::vector<std::pair<EGLDisplay, std::string>> candidate_displays(std::string* failures) {
  std::vector<std::pair<EGLDisplay, std::string>> out;
  const char* client_ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (has_extension(client_ext, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay d = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA,
                                         reinterpret_cast<void*>(EGL_DEFAULT_DISPLAY), nullptr);
    if (d != EGL_NO_DISPLAY) out.emplace_back(d, "surfaceless (Mesa)");
  } else {
    *failures += " no EGL_MESA_platform_surfaceless;";
  }
  if (has_extension(client_ext, "EGL_EXT_platform_device")) {
    auto query_devices =
        reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    EGLDeviceEXT devices[16];
    EGLint count = 0;
    if (query_devices != nullptr && query_devices(16, devices, &count)) {
      for (EGLint i = 0; i < count; ++i) {
        EGLDisplay d = eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
        if (d != EGL_NO_DISPLAY) out.emplace_back(d, "EGL device " + std::to_string(i));
      }
    }
  }
  EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY);
  if (d != EGL_NO_DISPLAY) {
    out.emplace_back(d, "default display");
  } else {
    *failures += " no default EGL display;";
  }
  return out;
}

}  // namespace

bool GlContext::Options::default_debug_output() {
  const char* env = std::getenv("LUCENT_GL_DEBUG");
  if (env != nullptr) return std::strcmp(env, "0") != 0;
#ifdef NDEBUG
  return false;
#else
  return true;
#endif
}

GlContext::GlContext(std::unique_ptr<Egl> egl) : egl_(std::move(egl)) {}

GlContext::~GlContext() {
  if (egl_ && egl_->display != EGL_NO_DISPLAY) {
    eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (egl_->context != EGL_NO_CONTEXT) eglDestroyContext(egl_->display, egl_->context);
    // The display is not terminated: EGL displays are shared per process, and other contexts
    // (another GlContext, a test's) may still use it.
  }
}

std::unique_ptr<GlContext> GlContext::create_headless(const Options& options) {
  std::string failures;
  for (auto& [display, platform] : candidate_displays(&failures)) {
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) {
      failures += " " + platform + ": eglInitialize " + egl_error_name(eglGetError()) + ";";
      continue;
    }
    const char* ext = eglQueryString(display, EGL_EXTENSIONS);
    if (!has_extension(ext, "EGL_KHR_surfaceless_context")) {
      failures += " " + platform + ": no EGL_KHR_surfaceless_context;";
      continue;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
      failures += " " + platform + ": no desktop OpenGL API;";
      continue;
    }
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!has_extension(ext, "EGL_KHR_no_config_context") &&
        !has_extension(ext, "EGL_MESA_configless_context")) {
      const EGLint attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
      EGLint n = 0;
      if (!eglChooseConfig(display, attributes, &config, 1, &n) || n == 0) {
        failures += " " + platform + ": no OpenGL-renderable EGL config;";
        continue;
      }
    }
    // 4.5 core exactly: Mesa llvmpipe offers 4.5 and refuses 4.6.
    const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                         4,
                                         EGL_CONTEXT_MINOR_VERSION,
                                         5,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                         EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                         EGL_CONTEXT_OPENGL_DEBUG,
                                         options.debug_output ? EGL_TRUE : EGL_FALSE,
                                         EGL_NONE};
    EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes);
    if (context == EGL_NO_CONTEXT) {
      failures +=
          " " + platform + ": no GL 4.5 core context (" + egl_error_name(eglGetError()) + ");";
      continue;
    }
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
      failures += " " + platform + ": eglMakeCurrent " + egl_error_name(eglGetError()) + ";";
      eglDestroyContext(display, context);
      continue;
    }
    auto egl = std::make_unique<Egl>();
    egl->display = display;
    egl->context = context;
    egl->platform = platform;
    std::unique_ptr<GlContext> result(new GlContext(std::move(egl)));
    if (options.debug_output) {
      glEnable(GL_DEBUG_OUTPUT);
      glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
      glDebugMessageCallback(debug_callback, nullptr);
    }
    return result;
  }
  if (failures.empty()) failures = " no EGL display at all (is libEGL / Mesa installed?)";
  throw Error("OpenGL: cannot create a headless OpenGL 4.5 core context through EGL:" + failures);
}

std::unique_ptr<GlContext> GlContext::try_create_headless(std::string* why_not) {
  try {
    return create_headless();
  } catch (const Error& e) {
    if (why_not != nullptr) *why_not = e.what();
    return nullptr;
  }
}

void GlContext::make_current() {
  if (!eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, egl_->context)) {
    throw Error("OpenGL: eglMakeCurrent failed: " + egl_error_name(eglGetError()));
  }
}

std::string GlContext::describe() const {
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  return std::string(renderer ? renderer : "?") + " | " + (version ? version : "?") + " (EGL " +
         egl_->platform + ")";
}

bool GlContext::is_software() const {
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  if (renderer == nullptr) return true;
  return std::strstr(renderer, "llvmpipe") || std::strstr(renderer, "softpipe") ||
         std::strstr(renderer, "swrast");
}

}  // namespace lucent::render
