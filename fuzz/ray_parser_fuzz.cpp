// libFuzzer target: the .ray parser (lexer + parser, strict and --lenient) on arbitrary text.
// obj_mesh and map() paths resolve against data/public-scenes, so seeds find their files.
#include "fuzz_entry.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    lc::fuzz::parseRay(data, size, LC_FUZZ_DATA_DIR);
  } catch (const lc::Error&) {
  }
  return 0;
}
