// Rendering one image with the processes of an MPI job (`mpirun -np K lightcuts render ...`,
// `srun`): every rank loads the scene and builds the same lights and light tree (both
// deterministic), rank 0 hands the tiles out one at a time from a queue while its own
// threads render too, and gathers the tiles, the reference pixels and every rank's
// statistics; it alone writes the image and reports. Each rank renders with its threads
// as a single process does.
//
// This header is MPI-free: distributed_mpi.cpp implements it with MPI (compiled when
// CMake finds MPI, LC_MPI), distributed_none.cpp without (one process, always).
//
// Faults: there is no blocking collective while rendering (the ranks poll), so a rank
// that dies is noticed by the launcher, which ends the job (Open MPI's mpirun does by
// default: the others get SIGTERM, then SIGKILL a second later); rank 0 then keeps the old
// output as for an interrupted render.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "render/renderer.h"

namespace lc::app {

class Cluster {
 public:
  virtual ~Cluster() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // The host this rank runs on.
  virtual std::string host() const = 0;
  // The work share of one render over every rank (rank 0 gathers); `cancel` stops waiting.
  virtual std::unique_ptr<render::WorkShare> workShare(std::atomic<bool>* cancel) = 0;
  // Rank 0 gets every rank's `text` by rank (its own first); the others send theirs and get
  // {}. Returns {} on rank 0 as well when `cancel` is set while waiting.
  virtual std::vector<std::string> gather(const std::string& text, std::atomic<bool>* cancel) = 0;
  // The clean end of a job (MPI_Finalize), called by every rank after its work. A rank
  // that fails or is interrupted exits without it, and the launcher ends the job.
  virtual void finish() = 0;
};

// Joins the MPI job this process was started in, or returns null when there is none: no
// MPI launcher's variables in the environment (OMPI_COMM_WORLD_SIZE, PMI_SIZE, PMIX_RANK),
// so MPI is never initialised for a plain run. Throws lc::Error when started by a launcher
// with several processes but built without MPI.
std::unique_ptr<Cluster> joinCluster();

// Whether this binary was built with MPI.
bool builtWithMpi();

}  // namespace lc::app
