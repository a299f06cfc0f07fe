// libFuzzer target: the PLY and OBJ readers and what load_mesh does after them (centring, scaling,
// orientation, normals), on arbitrary bytes.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "lucent/core/error.h"
#include "lucent/render/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  for (const bool ply : {true, false}) {
    try {
      lucent::render::Mesh mesh = ply ? lucent::render::parse_ply(bytes, "fuzz.ply")
                                      : lucent::render::parse_obj(bytes, "fuzz.obj");
      (void)lucent::render::finish_mesh(std::move(mesh), "fuzz", 100.0);
    } catch (const lucent::Error&) {
    }
  }
  return 0;
}
