// The simulated lens of a real rig: blur and veiling glare (simulate.h).
#include <algorithm>
#include <cmath>
#include <numbers>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "lucent/acquire/simulate.h"
#include "lucent/core/error.h"

namespace lucent::acquire {

imaging::ImageRgb apply_lens(const imaging::ImageRgb& image, double pixel_mm, double blur_mm,
                             double glare, double glare_radius_mm) {
  if (!(blur_mm >= 0 && blur_mm <= 100)) throw Error("--lens-blur-mm: expected 0..100 mm");
  if (!(glare >= 0 && glare < 1)) throw Error("--glare: expected a fraction in [0, 1)");
  if (!(glare_radius_mm > 0 && glare_radius_mm <= 1000))
    throw Error("--glare-radius-mm: expected (0, 1000] mm");
  if (!(pixel_mm > 0)) throw Error("lens: the pixel pitch must be > 0 mm");
  imaging::ImageRgb out = image;
  if (blur_mm == 0 && glare == 0) return out;
  cv::Mat m(image.height, image.width, CV_32FC3, out.data.data());  // a view of `out`
  if (blur_mm > 0) {
    const double s = blur_mm / pixel_mm;  // pixels
    cv::GaussianBlur(m, m, cv::Size(0, 0), s, s, cv::BORDER_CONSTANT);
  }
  if (glare > 0) {
    // The kernel over the whole field (light a pixel spreads beyond the image is lost, as in a
    // camera), normalised by its analytic integral over the plane: what falls outside the
    // truncated kernel is lost too.
    const int half = std::max(image.width, image.height);
    cv::Mat k(2 * half + 1, 2 * half + 1, CV_32F);
    const double a = glare_radius_mm, area = pixel_mm * pixel_mm;
    for (int y = -half; y <= half; ++y)
      for (int x = -half; x <= half; ++x) {
        const double r2 = (x * x + y * y) * area;
        k.at<float>(y + half, x + half) =
            float(a / (2 * std::numbers::pi * std::pow(r2 + a * a, 1.5)) * area);
      }
    cv::Mat veil;
    cv::filter2D(m, veil, -1, k, cv::Point(-1, -1), 0, cv::BORDER_CONSTANT);
    cv::addWeighted(m, 1 - glare, veil, glare, 0, m);
  }
  return out;
}

}  // namespace lucent::acquire
