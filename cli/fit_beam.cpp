// --beam-image (fit_beam.h).
#include "fit_beam.h"

#include <cmath>
#include <sstream>

#include "lucent/acquire/beam.h"
#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"

namespace lucent::cli {

void use_beam_image(std::vector<fit::ProfileData>& data, const std::string& path, double pixel_mm) {
  if (!(pixel_mm > 0)) {
    if (data.empty() || !(data.front().radial.pixel_mm > 0))
      throw Error("--beam-image " + path +
                  ": the image's pixel pitch on the target is unknown: give --beam-pixel-mm");
    pixel_mm = data.front().radial.pixel_mm;
  }
  imaging::ImageRgb image;
  try {
    image = imaging::read_any_image(path);
  } catch (const Error& e) {
    throw Error("--beam-image: " + std::string(e.what()));
  }
  if (image.width < 3 || image.height < 3)
    throw Error("--beam-image " + path + ": expected an image of the beam at least 3 x 3 pixels");
  std::vector<double> light(std::size_t(image.width) * std::size_t(image.height));
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      double sum = 0;
      for (int c = 0; c < 3; ++c) sum += image.at(x, y, c);
      light[std::size_t(y) * std::size_t(image.width) + std::size_t(x)] = sum / 3;
    }
  const acquire::SystemResponse r =
      acquire::system_response(light, image.width, image.height, pixel_mm);
  if (r.r_mm.size() < 2)
    throw Error("--beam-image " + path +
                ": no light in the image (every pixel 0 or below, or the spot on its edge)");
  std::ostringstream source;
  source << "the beam image " << path << " recorded";
  for (fit::ProfileData& d : data) {
    d.response_r_mm = r.r_mm;
    d.response_value = r.value;
    d.response_rms_mm = r.rms_mm;
    d.response_source = source.str();
  }
}

}  // namespace lucent::cli
