// Built without MPI (CMake did not find it, or LC_MPI=OFF): always one process.
#include <cstdlib>
#include <string>

#include "app/distributed.h"
#include "core/error.h"

namespace lc::app {

std::unique_ptr<Cluster> joinCluster() {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    const char* v = std::getenv(var);
    if (v && std::atoi(v) > 1)
      throw Error(std::string("started by an MPI launcher with ") + v +
                  " processes, but this lightcuts was built without MPI (install libopenmpi-dev and rebuild; "
                  "see README.md)");
  }
  return nullptr;
}

bool builtWithMpi() { return false; }

}  // namespace lc::app
