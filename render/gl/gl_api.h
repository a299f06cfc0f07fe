// The OpenGL 4.5 core API as lucent's renderer sources see it: prototypes straight from the Khronos
// header, resolved at link time against libOpenGL (GLVND), which exports every core entry point and
// dispatches to whichever context (EGL or GLX/GLFW) is current. No loader library is needed.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>
