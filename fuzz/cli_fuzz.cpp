// libFuzzer target: command-line argument sets (fuzz/cli_entry.h).
#include "cli_entry.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    lc::fuzz::parseArgs(data, size);
  } catch (const lc::Error&) {
  }
  return 0;
}
