// libFuzzer target: the OBJ/MTL loader. Input: OBJ text, optionally "\n%%MTL%%\n" and an
// MTL (written as f.mtl beside f.obj; the seeds say `mtllib f.mtl`).
#include "fuzz_entry.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    lc::fuzz::loadObj(data, size);
  } catch (const lc::Error&) {
  }
  return 0;
}
