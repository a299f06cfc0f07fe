// For tests of lucent's readers: an OpenEXR writer that writes whatever it is given, NaN and
// infinity included (lucent's own write_exr refuses non-finite pixels, as it must).
#pragma once

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include <filesystem>

#include "lucent/imaging/image.h"

namespace lucent::testing {

inline void write_raw_exr(const std::filesystem::path& path, const imaging::ImageRgb& image) {
  Imf::Header header(image.width, image.height);
  const char* names[3] = {"R", "G", "B"};
  for (const char* c : names) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
  Imf::OutputFile file(path.c_str(), header);
  Imf::FrameBuffer frame;
  char* base = reinterpret_cast<char*>(const_cast<float*>(image.data.data()));
  const std::size_t xs = 3 * sizeof(float), ys = xs * std::size_t(image.width);
  for (int c = 0; c < 3; ++c)
    frame.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
  file.setFrameBuffer(frame);
  file.writePixels(image.height);
}

}  // namespace lucent::testing
