// gl_api.h — the one place the GL backend includes OpenGL and EGL from: OpenGL 4.5 core
// prototypes (<GL/glcorearb.h>, linked against libglvnd's libOpenGL, which exports every
// core entry point, so no loader is needed) and EGL without X11 headers.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>

#ifndef EGL_NO_X11
#define EGL_NO_X11 1
#endif
#include <EGL/egl.h>
#include <EGL/eglext.h>
