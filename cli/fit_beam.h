// --beam-image: a bench's system response from an image of the beam on a white target, for
// captures without a white reference (no CLI11 here).
#pragma once

#include <string>
#include <vector>

#include "lucent/fit/fit_data.h"

namespace lucent::cli {

/// Reads `path` (OpenEXR, linear; or PNG/TIFF, whose codes are taken as linear) as the beam's light
/// on a flat white target through the same lens, pixels of pixel_mm on the target (0: the first
/// input's pixel pitch), and gives every input its radial system response (acquire::
/// system_response; over any the input carries). Throws lucent::Error naming the option and the file
/// when it cannot be read, holds no light, or its pixel pitch is unknown.
void use_beam_image(std::vector<fit::ProfileData>& data, const std::string& path, double pixel_mm);

}  // namespace lucent::cli
