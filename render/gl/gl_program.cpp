// Shader preprocessing, compilation and GL object owners (see gl_program.h).
#include "gl_program.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "gl_shader_sources.h"
#include "lucent/core/error.h"

namespace lucent::render::gl {

std::string shader_source(std::string_view name) {
  if (const char* dir = std::getenv("LUCENT_SHADER_DIR"); dir != nullptr && *dir != '\0') {
    std::ifstream in(std::string(dir) + "/" + std::string(name));
    if (in) {
      std::ostringstream s;
      s << in.rdbuf();
      return s.str();
    }
  }
  for (const EmbeddedShader& s : embedded_shaders()) {
    if (s.name == name) return std::string(s.text);
  }
  throw Error("OpenGL: no shader named '" + std::string(name) + "' is embedded in lucent");
}

std::vector<std::string> shader_names() {
  std::vector<std::string> names;
  for (const EmbeddedShader& s : embedded_shaders()) names.emplace_back(s.name);
  return names;
}

namespace {

// Appends `source` (file number `index`) to `out`, expanding #include "x" recursively, each file
// once (the include files also carry guards).
void expand(std::string_view name, std::string_view source, std::ostringstream& out,
            std::vector<std::string>* file_names, std::set<std::string>* seen, int depth) {
  if (depth > 16)
    throw Error("OpenGL: shader includes nest too deeply at '" + std::string(name) + "'");
  const int index = int(file_names->size());
  file_names->emplace_back(name);
  std::istringstream in{std::string(source)};
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t");
    if (first != std::string::npos && line.compare(first, 8, "#include") == 0) {
      const auto open = line.find('"', first);
      const auto close = open == std::string::npos ? open : line.find('"', open + 1);
      if (close == std::string::npos) {
        throw Error("OpenGL: " + std::string(name) + ":" + std::to_string(number) +
                    ": malformed #include");
      }
      const std::string included = line.substr(open + 1, close - open - 1);
      if (seen->insert(included).second) {
        expand(included, shader_source(included), out, file_names, seen, depth + 1);
      }
      out << "#line " << number + 1 << " " << index << "\n";
      continue;
    }
    out << line << "\n";
  }
}

}  // namespace

std::string preprocess_shader(std::string_view name, std::string_view source,
                              const std::vector<std::string>& defines,
                              std::vector<std::string>* file_names) {
  // The #version line must come first; defines follow it.
  const std::string text(source);
  const auto version = text.find("#version");
  if (version == std::string::npos) {
    throw Error("OpenGL: shader '" + std::string(name) + "' has no #version line");
  }
  const auto eol = text.find('\n', version);
  std::ostringstream out;
  out << text.substr(0, eol + 1);
  for (const std::string& d : defines) out << "#define " << d << "\n";
  int version_line = 1;
  for (std::size_t i = 0; i < eol; ++i) version_line += text[i] == '\n';
  file_names->clear();
  std::set<std::string> seen{std::string(name)};
  std::ostringstream body;
  expand(name, std::string_view(text).substr(eol + 1), body, file_names, &seen, 0);
  out << "#line " << version_line + 1 << " 0\n" << body.str();
  return out.str();
}

namespace {

// Replaces "0(12)" / "0:12" style file numbers at line starts in a driver log with file names.
std::string translate_log(const std::string& log, const std::vector<std::string>& files) {
  std::istringstream in(log);
  std::ostringstream out;
  std::string line;
  while (std::getline(in, line)) {
    std::size_t p = 0;
    while (p < line.size() && line[p] == ' ') ++p;
    // Mesa: "0:12(3): error: ..."; NVIDIA: "0(12) : error ...".
    std::size_t q = p;
    while (q < line.size() && std::isdigit(static_cast<unsigned char>(line[q]))) ++q;
    if (q > p && q < line.size() && (line[q] == ':' || line[q] == '(')) {
      const int index = std::atoi(line.substr(p, q - p).c_str());
      if (index >= 0 && index < int(files.size())) {
        line = line.substr(0, p) + files[std::size_t(index)] + line.substr(q);
      }
    }
    out << line << "\n";
  }
  return out.str();
}

GLuint compile(GLenum type, std::string_view name, std::string_view source,
               const std::vector<std::string>& defines) {
  std::vector<std::string> files;
  const std::string text = preprocess_shader(name, source, defines, &files);
  const GLuint shader = glCreateShader(type);
  const char* p = text.c_str();
  glShaderSource(shader, 1, &p, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(std::size_t(std::max(length, 1)), '\0');
    glGetShaderInfoLog(shader, length, nullptr, log.data());
    glDeleteShader(shader);
    throw Error("OpenGL: shader '" + std::string(name) + "' does not compile:\n" +
                translate_log(log, files));
  }
  return shader;
}

GLuint link(const std::vector<GLuint>& shaders, const std::string& what) {
  const GLuint program = glCreateProgram();
  for (GLuint s : shaders) glAttachShader(program, s);
  glLinkProgram(program);
  for (GLuint s : shaders) {
    glDetachShader(program, s);
    glDeleteShader(s);
  }
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
    std::string log(std::size_t(std::max(length, 1)), '\0');
    glGetProgramInfoLog(program, length, nullptr, log.data());
    glDeleteProgram(program);
    throw Error("OpenGL: program (" + what + ") does not link:\n" + log);
  }
  return program;
}

}  // namespace

Program::Program(std::initializer_list<ShaderStage> stages,
                 const std::vector<std::string>& defines) {
  std::vector<GLuint> shaders;
  std::string what;
  try {
    for (const ShaderStage& s : stages) {
      shaders.push_back(compile(s.type, s.file, shader_source(s.file), defines));
      what += (what.empty() ? "" : ", ") + s.file;
    }
  } catch (...) {
    for (GLuint s : shaders) glDeleteShader(s);
    throw;
  }
  id_ = link(shaders, what);
}

Program Program::from_source(GLenum type, std::string_view name, std::string_view source,
                             const std::vector<std::string>& defines) {
  Program p;
  p.id_ = link({compile(type, name, source, defines)}, std::string(name));
  return p;
}

Program::~Program() {
  if (id_ != 0) glDeleteProgram(id_);
}

Program& Program::operator=(Program&& o) noexcept {
  if (this != &o) {
    if (id_ != 0) glDeleteProgram(id_);
    id_ = std::exchange(o.id_, 0);
  }
  return *this;
}

void delete_texture(GLsizei n, const GLuint* ids) {
  glDeleteTextures(n, ids);
}
void delete_buffer(GLsizei n, const GLuint* ids) {
  glDeleteBuffers(n, ids);
}
void delete_framebuffer(GLsizei n, const GLuint* ids) {
  glDeleteFramebuffers(n, ids);
}
void delete_renderbuffer(GLsizei n, const GLuint* ids) {
  glDeleteRenderbuffers(n, ids);
}
void delete_vertex_array(GLsizei n, const GLuint* ids) {
  glDeleteVertexArrays(n, ids);
}
void delete_sampler(GLsizei n, const GLuint* ids) {
  glDeleteSamplers(n, ids);
}
void delete_query(GLsizei n, const GLuint* ids) {
  glDeleteQueries(n, ids);
}

Texture create_texture(GLenum target) {
  GLuint id = 0;
  glCreateTextures(target, 1, &id);
  return Texture(id);
}
Buffer create_buffer() {
  GLuint id = 0;
  glCreateBuffers(1, &id);
  return Buffer(id);
}
Framebuffer create_framebuffer() {
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  return Framebuffer(id);
}
Renderbuffer create_renderbuffer() {
  GLuint id = 0;
  glCreateRenderbuffers(1, &id);
  return Renderbuffer(id);
}
VertexArray create_vertex_array() {
  GLuint id = 0;
  glCreateVertexArrays(1, &id);
  return VertexArray(id);
}
Sampler create_sampler() {
  GLuint id = 0;
  glCreateSamplers(1, &id);
  return Sampler(id);
}
Query create_query(GLenum target) {
  GLuint id = 0;
  glCreateQueries(target, 1, &id);
  return Query(id);
}

void check_errors(const char* what) {
  GLenum first = GL_NO_ERROR;
  for (GLenum e; (e = glGetError()) != GL_NO_ERROR;) {
    if (first == GL_NO_ERROR) first = e;
  }
  if (first != GL_NO_ERROR) {
    std::ostringstream s;
    s << "OpenGL: error 0x" << std::hex << first << " in " << what;
    throw Error(s.str());
  }
}

void check_framebuffer(GLuint framebuffer, const char* what) {
  const GLenum status = glCheckNamedFramebufferStatus(framebuffer, GL_DRAW_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    std::ostringstream s;
    s << "OpenGL: framebuffer for " << what << " is incomplete (status 0x" << std::hex << status
      << ")";
    throw Error(s.str());
  }
}

}  // namespace lucent::render::gl
