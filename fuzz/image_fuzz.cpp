// libFuzzer target: image decoding (io::readImage: EXR via OpenEXR, PNG via libpng, JPEG via
// libjpeg-turbo, BMP/TGA/PNM/HDR via stb_image), with the texture pixel limit small.
#include "fuzz_entry.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    lc::fuzz::readImage(data, size);
  } catch (const lc::Error&) {
  }
  return 0;
}
