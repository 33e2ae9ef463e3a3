// libFuzzer target: what `lightcuts compare` does with two images from anywhere
// (fuzz_entry.h's compareImages: any format, a small pixel limit, metrics and heatmap over
// whatever values they hold: NaN, inf, negative, huge).
#include "fuzz_entry.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    lc::fuzz::compareImages(data, size);
  } catch (const lc::Error&) {
  }
  return 0;
}
