// write_dng: a minimal uncompressed Bayer DNG through libtiff (see camera_raw.h).
#include <tiffio.h>

#include <cmath>
#include <memory>
#include <string>

#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/imaging/camera_raw.h"

namespace lucent::imaging {
namespace {

struct TiffCloser {
  void operator()(TIFF* tif) const { TIFFClose(tif); }
};

}  // namespace

void write_dng(const std::filesystem::path& path, const BayerMosaic& m) {
  if (m.width < 2 || m.height < 2 || m.width % 2 || m.height % 2 ||
      m.data.size() != std::size_t(m.width) * m.height) {
    throw Error(path.string() +
                ": a Bayer mosaic needs an even width and height and one code per "
                "photosite");
  }
  if (!(m.black_level >= 0 && m.black_level < m.white_level && m.white_level <= 65535)) {
    throw Error(path.string() + ": expected 0 <= black level < white level <= 65535");
  }
  AtomicOutputPath out(path);
  {
    std::unique_ptr<TIFF, TiffCloser> tif(TIFFOpen(out.temporary().c_str(), "w"));
    if (!tif) throw Error(path.string() + ": cannot create the DNG file");
    TIFF* t = tif.get();
    const std::uint8_t version[4] = {1, 4, 0, 0}, backward[4] = {1, 1, 0, 0};
    const std::uint16_t repeat[2] = {2, 2};
    std::uint8_t pattern[4];
    for (int q = 0; q < 4; ++q) pattern[q] = std::uint8_t(m.pattern[q]);
    const float black = float(m.black_level);
    const std::uint32_t white = std::uint32_t(m.white_level);
    const float identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    const float neutral[3] = {1, 1, 1};
    const std::string model = m.make + " " + m.model;
    bool ok =
        TIFFSetField(t, TIFFTAG_SUBFILETYPE, 0) && TIFFSetField(t, TIFFTAG_IMAGEWIDTH, m.width) &&
        TIFFSetField(t, TIFFTAG_IMAGELENGTH, m.height) &&
        TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, 16) && TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, 1) &&
        TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_NONE) &&
        TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_CFA) &&
        TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG) &&
        TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, m.height) &&
        TIFFSetField(t, TIFFTAG_MAKE, m.make.c_str()) &&
        TIFFSetField(t, TIFFTAG_MODEL, m.model.c_str()) &&
        TIFFSetField(t, TIFFTAG_DNGVERSION, version) &&
        TIFFSetField(t, TIFFTAG_DNGBACKWARDVERSION, backward) &&
        TIFFSetField(t, TIFFTAG_UNIQUECAMERAMODEL, model.c_str()) &&
        TIFFSetField(t, TIFFTAG_CFAREPEATPATTERNDIM, repeat) &&
        TIFFSetField(t, TIFFTAG_CFAPATTERN, 4, pattern) &&
        TIFFSetField(t, TIFFTAG_BLACKLEVEL, 1, &black) &&
        TIFFSetField(t, TIFFTAG_WHITELEVEL, 1, &white) &&
        TIFFSetField(t, TIFFTAG_COLORMATRIX1, 9, identity) &&
        TIFFSetField(t, TIFFTAG_ASSHOTNEUTRAL, 3, neutral);
    // Exposure time and ISO live in an EXIF directory: its offset is known only once it is
    // written, so IFD 0 reserves the pointer, and is rewritten with it at the end (libtiff's way).
    const bool exif = m.exposure_s > 0 || m.iso > 0;
    if (ok && exif) ok = TIFFSetField(t, TIFFTAG_EXIFIFD, std::uint64_t(0));
    if (!ok) throw Error(path.string() + ": cannot set the DNG tags");
    for (int row = 0; row < m.height; ++row) {
      std::uint16_t* line = const_cast<std::uint16_t*>(m.data.data() + std::size_t(row) * m.width);
      if (TIFFWriteScanline(t, line, std::uint32_t(row), 0) < 0) {
        throw Error(path.string() + ": cannot write the DNG pixels");
      }
    }
    if (exif) {
      std::uint64_t exif_offset = 0;
      ok = TIFFWriteDirectory(t) && TIFFCreateEXIFDirectory(t) == 0;
      if (ok && m.exposure_s > 0) ok = TIFFSetField(t, EXIFTAG_EXPOSURETIME, m.exposure_s);
      if (ok && m.iso > 0) {
        const std::uint16_t iso = std::uint16_t(std::lround(std::min(m.iso, 65535.0)));
        ok = TIFFSetField(t, EXIFTAG_ISOSPEEDRATINGS, 1, &iso);
      }
      ok = ok && TIFFWriteCustomDirectory(t, &exif_offset) && TIFFSetDirectory(t, 0) &&
           TIFFSetField(t, TIFFTAG_EXIFIFD, exif_offset) && TIFFWriteDirectory(t);
      if (!ok) throw Error(path.string() + ": cannot write the DNG's EXIF directory");
    }
  }
  out.commit();
}

}  // namespace lucent::imaging
