// lucent.render: a still image of a material on a mesh by any technique, headless (EGL), as a
// NumPy array of linear radiance, from the flags `lucent render` takes.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <sstream>

#include "bindings.h"
#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"
#include "lucent/render/technique.h"
#include "scene_from_flags.h"

namespace lucent::python {
namespace {

py::array_t<float> array_of(const imaging::ImageRgb& image) {
  py::array_t<float> out({py::ssize_t(image.height), py::ssize_t(image.width), py::ssize_t{3}});
  std::copy(image.data.begin(), image.data.end(), out.mutable_data());  // row-major RGB
  return out;
}

// A keyword as its flag: maps_directions -> --maps-directions.
std::string flag_of(const std::string& key) {
  std::string flag = "--" + key;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

// A keyword's value as the flag's text: numbers as Python writes them, sequences comma-joined
// (light=[...] gives one --light per item), True/False as on/off.
std::vector<std::string> flag_values(const py::handle& value) {
  if (py::isinstance<py::bool_>(value)) return {value.cast<bool>() ? "on" : "off"};
  if (py::isinstance<py::str>(value)) return {value.cast<std::string>()};
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    std::vector<std::string> items;
    for (const py::handle item : value) items.push_back(py::str(item).cast<std::string>());
    return items;
  }
  return {py::str(value).cast<std::string>()};
}

}  // namespace

void bind_render(py::module_& m) {
  m.def(
      "render",
      [](const std::string& material, const py::kwargs& options) {
        std::vector<std::string> flags{"--material", material};
        // `lucent render`'s own default size (the scene options leave it to the command).
        if (!options.contains("size")) flags.insert(flags.end(), {"--size", "256x256"});
        for (const auto& [key, value] : options) {
          const std::string k = key.cast<std::string>();
          const std::string flag = flag_of(k);
          if (!cli::is_scene_flag(flag))
            throw Error(k + ": not an option of lucent.render (`lucent render` has no " + flag +
                        ")");
          if (k == "light" || k == "lights") {  // repeatable: one flag per light
            for (const std::string& v : flag_values(value))
              flags.insert(flags.end(), {"--light", v});
          } else {
            const std::vector<std::string> values = flag_values(value);
            std::ostringstream joined;
            for (std::size_t i = 0; i < values.size(); ++i) joined << (i ? "," : "") << values[i];
            flags.insert(flags.end(), {flag, joined.str()});
          }
        }
        const cli::FlagScene s = cli::scene_from_flags(flags);
        render::ImageRgb image;
        {
          py::gil_scoped_release release;
          image = render::render_still(s.technique, s.scene, s.options, nullptr);
        }
        return array_of(image);
      },
      py::arg("material"),
      "a still image of the material, headless: an (H, W, 3) float32 array of linear radiance, row "
      "0 at the top. Keywords are `lucent render`'s flags with _ for - (technique='maps', "
      "mesh='bunny', size='64x48', light=['directional:0,0,1:1,1,1'], maps_directions=8, "
      "specular=False, ...): the same checks, the same image, run whole (no budget)");
  m.def(
      "read_image",
      [](const std::filesystem::path& path) {
        imaging::ImageRgb image;
        {
          py::gil_scoped_release release;
          image = imaging::read_any_image(path);
        }
        return array_of(image);
      },
      py::arg("path"),
      "an image file (OpenEXR, Radiance HDR, PNG, TIFF) as an (H, W, 3) float32 array, linear "
      "for the HDR formats");
}

}  // namespace lucent::python
