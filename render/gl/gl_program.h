// GLSL programs built from the shaders embedded at build time (render/gl/shaders and
// render/techniques/*/shaders, see render/gl_sources.cmake), with `#include "file.glsl"` resolved
// here (GL 4.5 core has no include mechanism), `#define`s injected after `#version`, and compile
// errors reported with file names. Also small RAII owners for GL objects. Needs a current GL
// context.
#pragma once

#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gl_api.h"

namespace lucent::render::gl {

/// The text of an embedded shader file by name ("radiance_map.frag"). $LUCENT_SHADER_DIR, when set,
/// is read first (edit shaders without rebuilding). Throws lucent::Error for unknown names.
std::string shader_source(std::string_view name);

/// Names of all embedded shader files.
std::vector<std::string> shader_names();

/// `source` with its #include lines expanded (each file once) and `defines` ("NAME VALUE" or
/// "NAME") inserted after the #version line; `#line` directives number the files, and *file_names
/// receives the name for each file number so compile logs can be translated.
std::string preprocess_shader(std::string_view name, std::string_view source,
                              const std::vector<std::string>& defines,
                              std::vector<std::string>* file_names);

struct ShaderStage {
  GLenum type;       ///< GL_VERTEX_SHADER, ...
  std::string file;  ///< embedded file name
};

/// An owned program object.
class Program {
 public:
  Program() = default;
  /// Compiles and links the stages; throws lucent::Error with the log (file names restored).
  Program(std::initializer_list<ShaderStage> stages, const std::vector<std::string>& defines = {});
  /// As above from literal source for one stage (tests' compute kernels); includes resolve against
  /// the embedded files.
  static Program from_source(GLenum type, std::string_view name, std::string_view source,
                             const std::vector<std::string>& defines = {});
  ~Program();
  Program(Program&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  Program& operator=(Program&& o) noexcept;
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  GLuint id() const { return id_; }
  void use() const { glUseProgram(id_); }
  /// Location of a uniform, -1 when the compiler removed it (setting -1 is a no-op in GL).
  GLint location(const char* name) const { return glGetUniformLocation(id_, name); }

 private:
  GLuint id_ = 0;
};

/// Owner of GL names made by glCreate*/glGen* and freed by the matching glDelete*.
template <void (*Delete)(GLsizei, const GLuint*)>
class Name {
 public:
  Name() = default;
  explicit Name(GLuint id) : id_(id) {}
  ~Name() { reset(); }
  Name(Name&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  Name& operator=(Name&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, 0);
    }
    return *this;
  }
  Name(const Name&) = delete;
  Name& operator=(const Name&) = delete;
  GLuint id() const { return id_; }
  void reset() {
    if (id_ != 0) Delete(1, &id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};

void delete_texture(GLsizei n, const GLuint* ids);
void delete_buffer(GLsizei n, const GLuint* ids);
void delete_framebuffer(GLsizei n, const GLuint* ids);
void delete_renderbuffer(GLsizei n, const GLuint* ids);
void delete_vertex_array(GLsizei n, const GLuint* ids);
void delete_sampler(GLsizei n, const GLuint* ids);
void delete_query(GLsizei n, const GLuint* ids);

using Texture = Name<delete_texture>;
using Buffer = Name<delete_buffer>;
using Framebuffer = Name<delete_framebuffer>;
using Renderbuffer = Name<delete_renderbuffer>;
using VertexArray = Name<delete_vertex_array>;
using Sampler = Name<delete_sampler>;
using Query = Name<delete_query>;

Texture create_texture(GLenum target);
Buffer create_buffer();
Framebuffer create_framebuffer();
Renderbuffer create_renderbuffer();
VertexArray create_vertex_array();
Sampler create_sampler();
Query create_query(GLenum target);

/// Throws lucent::Error naming `what` if glGetError reports anything (drains the error queue).
void check_errors(const char* what);

/// Throws lucent::Error naming `what` if `framebuffer` is incomplete.
void check_framebuffer(GLuint framebuffer, const char* what);

}  // namespace lucent::render::gl
