// The twin tests' compute-kernel harness (white-box: it uses render/'s private gl_program.h):
// a GLSL function run on configurations in a storage buffer, its results read back.
#pragma once

#include <cstddef>
#include <vector>

#include "gl_api.h"
#include "gl_program.h"

namespace lucent::render::testing_gl {

/// Runs a twin test's compute kernel (local size 64; reads `input` from the storage buffer at
/// binding 0, writes `outputs` floats per configuration to binding 1; `u_count` configurations)
/// and returns what it wrote.
inline std::vector<float> run_kernel(const gl::Program& program, const std::vector<float>& input,
                                     std::size_t count, std::size_t outputs,
                                     const char* what) {
  gl::Buffer in = gl::create_buffer(), out = gl::create_buffer();
  glNamedBufferStorage(in.id(), GLsizeiptr(input.size() * sizeof(float)), input.data(), 0);
  glNamedBufferStorage(out.id(), GLsizeiptr(count * outputs * sizeof(float)), nullptr,
                       GL_MAP_READ_BIT);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.id());
  program.use();
  glUniform1i(program.location("u_count"), GLint(count));
  glDispatchCompute(GLuint((count + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<float> result(count * outputs);
  glGetNamedBufferSubData(out.id(), 0, GLsizeiptr(result.size() * sizeof(float)), result.data());
  gl::check_errors(what);
  return result;
}

}  // namespace lucent::render::testing_gl
