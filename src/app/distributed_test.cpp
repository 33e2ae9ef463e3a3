// Distributed rendering under mpirun (issue 27; app/distributed.h), end to end:
//   - 2 and 3 ranks give the image of one process bit for bit (reconstruction cuts with
//     tiles shared across ranks, several samples per pixel, reference pixels), and --stats
//     adds every rank's counters and reports each rank under "mpi";
//   - a rank killed mid-render fails the job within seconds and leaves the old output;
//   - SIGINT to mpirun keeps the old output and saves the partial image, as for one process.
// Skipped when the binary was built without MPI or mpirun is missing (LC_MPIEXEC, from
// CMake). CI runs as root: mpirun needs --allow-run-as-root and the OMPI_ALLOW_RUN_AS_ROOT
// variables. Under the sanitizer build (make test-sanitize) LeakSanitizer's reports of
// Open MPI's own allocations are suppressed (tests/lsan_mpi.supp).
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "child_process.h"
#include "test_util.h"

namespace fs = std::filesystem;
using lc::testing::ChildProcess;
using lc::testing::TempDir;
using lc::testing::filesIn;
using lc::testing::scenePath;
using lc::testing::slurp;

namespace {

using Clock = std::chrono::steady_clock;

// $LC_MPIEXEC, else the mpiexec CMake found ("" when built without MPI).
std::string mpiexec() {
  const char* m = std::getenv("LC_MPIEXEC");
  return m ? m : LC_MPIEXEC;
}

#define SKIP_WITHOUT_MPI()                                                                 \
  do {                                                                                     \
    if (mpiexec().empty() || !fs::exists(mpiexec()))                                       \
      GTEST_SKIP() << "lightcuts built without MPI, or no mpirun (LC_MPIEXEC='" << mpiexec() << "')"; \
  } while (0)

// The environment mpirun and its ranks need here: root allowed (CI runs as root), and under
// the sanitizer build Open MPI's leaks suppressed.
void prepareEnvironment() {
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  // LeakSanitizer can match Open MPI's leaks to its libraries only when its plugins stay
  // loaded (no dlclose at MPI_Finalize: their frames would be "<unknown module>") and the
  // stacks are unwound in full (Open MPI is built without frame pointers). Harmless
  // without the sanitizers.
  setenv("OMPI_MCA_mca_base_component_disable_dlclose", "1", 1);
  std::string supp = "suppressions=" + lc::testing::sourceDir() +
                     "/tests/lsan_mpi.supp:print_suppressions=0:fast_unwind_on_malloc=0";
  const char* old = std::getenv("LSAN_OPTIONS");
  if (!old || std::string(old).find("lsan_mpi.supp") == std::string::npos)
    setenv("LSAN_OPTIONS", old && *old ? (std::string(old) + ":" + supp).c_str() : supp.c_str(), 1);
}

// `mpirun -np K lightcuts ARGS` (K = 0: lightcuts alone) in `dir`, output captured.
ChildProcess startJob(int ranks, const std::vector<std::string>& args, const std::string& dir) {
  prepareEnvironment();
  std::vector<std::string> launcher;
  if (ranks > 0) launcher = {mpiexec(), "--allow-run-as-root", "--oversubscribe", "-np", std::to_string(ranks)};
  return ChildProcess(lc::testing::lightcutsCommand(args, launcher), dir);
}

// The process of rank `rank` among the launcher's descendants (by OMPI_COMM_WORLD_RANK in
// its environment), or -1.
pid_t rankProcess(pid_t launcher, int rank) {
  auto parentOf = [](pid_t p) -> pid_t {
    std::string stat = slurp("/proc/" + std::to_string(p) + "/stat");
    size_t close = stat.rfind(')');
    if (close == std::string::npos) return -1;
    char state = 0;
    int ppid = -1;
    if (sscanf(stat.c_str() + close + 1, " %c %d", &state, &ppid) != 2) return -1;
    return ppid;
  };
  const std::string want = std::string("OMPI_COMM_WORLD_RANK=") + std::to_string(rank);
  for (const auto& e : fs::directory_iterator("/proc")) {
    std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    pid_t p = std::stoi(name);
    bool descendant = false;
    for (pid_t q = p; q > 1; q = parentOf(q))
      if (q == launcher) {
        descendant = true;
        break;
      }
    if (!descendant) continue;
    std::string env = slurp("/proc/" + name + "/environ");
    for (size_t i = 0; i < env.size();) {
      size_t end = env.find('\0', i);
      if (end == std::string::npos) end = env.size();
      if (env.compare(i, end - i, want) == 0 && slurp("/proc/" + name + "/comm").rfind("lightcuts", 0) == 0) return p;
      i = end + 1;
    }
  }
  return -1;
}

struct Variant {
  std::string name;
  std::vector<std::string> args;
};

// Renders `args` with one process and with 2 and 3 ranks; the EXR images (exact floats)
// and cut-size heatmaps must match byte for byte.
void expectSameImages(const Variant& v) {
  TempDir dir;
  // Each run in its own folder under the same file names: the images' metadata holds the
  // command line, which must not differ either.
  auto sub = [&](int ranks) { return dir.path() + "/r" + std::to_string(ranks); };
  auto renderWith = [&](int ranks) {
    fs::create_directories(sub(ranks));
    fs::copy_file(scenePath("cornell_box.ray"), sub(ranks) + "/scene.ray");
    std::vector<std::string> args{"render", "scene.ray", "-o", "img.exr", "--stats", "stats.json",
                                  "--cut-heatmap", "cut.png", "--threads", "1"};
    args.insert(args.end(), v.args.begin(), v.args.end());
    ChildProcess job = startJob(ranks, args, sub(ranks));
    EXPECT_TRUE(job.wait(600)) << v.name << ", " << ranks << " ranks: timed out";
    EXPECT_EQ(job.shellStatus(), 0) << v.name << ", " << ranks << " ranks:\n" << job.stderrText();
    return nlohmann::json::parse(slurp(sub(ranks) + "/stats.json"), nullptr, false);
  };
  nlohmann::json one = renderWith(0);
  ASSERT_FALSE(one.is_discarded());
  EXPECT_FALSE(one.contains("mpi"));
  const std::string image = slurp(sub(0) + "/img.exr"), cuts = slurp(sub(0) + "/cut.png");
  ASSERT_GT(image.size(), 1000u);
  for (int ranks : {2, 3}) {
    SCOPED_TRACE(v.name + ", " + std::to_string(ranks) + " ranks");
    nlohmann::json j = renderWith(ranks);
    ASSERT_FALSE(j.is_discarded());
    EXPECT_TRUE(slurp(sub(ranks) + "/img.exr") == image) << "the image differs from one process'";
    EXPECT_TRUE(slurp(sub(ranks) + "/cut.png") == cuts) << "the cut heatmap differs from one process'";
    ASSERT_TRUE(j.contains("mpi"));
    EXPECT_EQ(j["mpi"]["ranks"], ranks);
    ASSERT_EQ(j["mpi"]["per_rank"].size(), size_t(ranks));
    uint64_t pixels = 0, tiles = 0, refPixels = 0;
    for (int r = 0; r < ranks; ++r) {
      const auto& pr = j["mpi"]["per_rank"][size_t(r)];
      EXPECT_EQ(pr["rank"], r);
      pixels += pr["pixels"].get<uint64_t>();
      tiles += pr["tiles"].get<uint64_t>();
      refPixels += pr["reference_pixels"].get<uint64_t>();
      EXPECT_FALSE(pr.contains("counters"));
    }
    EXPECT_EQ(pixels, one["width"].get<uint64_t>() * one["height"].get<uint64_t>());
    EXPECT_GT(tiles, 0u);
    double lb = j["mpi"]["load_balance"].get<double>();
    EXPECT_GT(lb, 0.0);
    EXPECT_LE(lb, 1.0);
    // The reference pixels are split over the ranks and gathered: the same error.
    if (one.contains("reference")) {
      EXPECT_EQ(refPixels, one["reference"]["pixels"].get<uint64_t>());
      EXPECT_EQ(j["reference"]["pixels"], one["reference"]["pixels"]);
      EXPECT_EQ(j["reference"]["mean_relative_error"], one["reference"]["mean_relative_error"]);
      EXPECT_EQ(j["reference"]["max_relative_error"], one["reference"]["max_relative_error"]);
      EXPECT_EQ(j["reference"]["worst_pixels"], one["reference"]["worst_pixels"]);
      EXPECT_EQ(j["reference"]["brute_lights_per_shading_point"], one["reference"]["brute_lights_per_shading_point"]);
    }
    // Without reconstruction cuts no pixel is traced twice: the counters add up exactly.
    if (one["reconstruct_spacing"].get<int>() <= 1) {
      EXPECT_EQ(j["primary_rays"], one["primary_rays"]);
      EXPECT_EQ(j["shadow_rays"], one["shadow_rays"]);
      EXPECT_EQ(j["shading_points"], one["shading_points"]);
      EXPECT_EQ(j["cut_histogram"], one["cut_histogram"]);
    } else {  // samples on tile edges are traced by both ranks' tiles where they differ
      EXPECT_GE(j["primary_rays"].get<uint64_t>(), one["primary_rays"].get<uint64_t>());
    }
    EXPECT_EQ(j["lights"], one["lights"]);
  }
}

TEST(Distributed, SameImageAsOneProcessWithReconstructionCuts) {
  SKIP_WITHOUT_MPI();
  // Tiles of 64 pixels (coarse cells of 8): 3 x 3 tiles whose edge samples are made on
  // different ranks.
  expectSameImages({"reconstruction cuts", {"--width", "160", "--height", "160", "--reconstruct", "4",
                                             "--reference-pixels", "40"}});
}

TEST(Distributed, SameImageAsOneProcessWithSupersampling) {
  SKIP_WITHOUT_MPI();
  expectSameImages({"2 spp, no reconstruction", {"--width", "72", "--height", "56", "--spp", "2", "--reconstruct", "0",
                                                 "--reference-pixels", "30"}});
}

// Every rank meets the same bad input: the job fails with rank 0's message, once.
TEST(Distributed, AnErrorIsReportedOnceAndFailsTheJob) {
  SKIP_WITHOUT_MPI();
  TempDir dir;
  std::ofstream(dir.file("bad.ray")) << "SBT-raytracer 1.0\ncamera { position = (0,0,10)\n";
  ChildProcess job = startJob(2, {"render", "bad.ray", "-o", "out.png"}, dir.path());
  ASSERT_TRUE(job.wait(60));
  EXPECT_EQ(job.shellStatus(), 1) << job.stderrText();
  const std::string msg = "lightcuts: bad.ray:3:1: error: expected '}' to close camera opened at 2:8, got end of file";
  std::string err = job.stderrText();
  size_t first = err.find(msg);
  ASSERT_NE(first, std::string::npos) << err;
  EXPECT_EQ(err.find(msg, first + 1), std::string::npos) << "reported more than once:\n" << err;
  EXPECT_EQ(err.find("rank 1"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir.file("out.png")));
}

// A scene that takes minutes to render by brute force: 600 point lights over a plane.
std::string slowScene() {
  std::string s = "SBT-raytracer 1.0\ncamera { position = (0,0,10); viewdir = (0,0,-1); }\n";
  for (int i = 0; i < 600; ++i)
    s += "point_light { position = (" + std::to_string(i % 25 - 12) + "," + std::to_string(i / 25 - 12) +
         ",3); colour = (0.01,0.01,0.01); }\n";
  s += "scale(20, square { material = { diffuse = (1,1,1); }; })\nsphere { material = { diffuse = (1,0,0); }; }\n";
  return s;
}

// 400 x 400 pixels of 16 samples: a minute on one thread, and a small partial image to write
// in the second mpirun leaves between SIGTERM and SIGKILL.
const std::vector<std::string> kSlowRender{"render",  "slow.ray", "-o",   "out.png",   "--method", "brute", "--width",
                                           "400",     "--height", "400",  "--spp",     "16",       "--threads", "1"};

TEST(Distributed, KilledRankFailsTheJobAndKeepsTheOldOutput) {
  SKIP_WITHOUT_MPI();
  TempDir dir;
  std::ofstream(dir.file("slow.ray")) << slowScene();
  const std::string old = "previous image: must survive the failed job byte for byte";
  std::ofstream(dir.file("out.png")) << old;
  ChildProcess job = startJob(2, kSlowRender, dir.path());
  // Rank 0's progress line appears once rendering has run for a second.
  ASSERT_TRUE(job.waitForStderr("rendering", 120)) << job.stderrText();
  pid_t victim = rankProcess(job.pid(), 1);
  ASSERT_GT(victim, 0) << "no rank 1 among mpirun's processes";
  auto t0 = Clock::now();
  kill(victim, SIGKILL);
  ASSERT_TRUE(job.wait(30)) << "the job did not end after a rank was killed";
  double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  RecordProperty("seconds_to_fail", std::to_string(seconds));
  std::printf("job failed %.2f s after rank 1 was killed (exit %d)\n", seconds, job.shellStatus());
  EXPECT_NE(job.shellStatus(), 0) << job.stderrText();
  EXPECT_LT(seconds, 10.0);
  EXPECT_EQ(slurp(dir.file("out.png")), old);
  // The launcher names the rank that died.
  EXPECT_NE(job.stderrText().find("signal 9"), std::string::npos) << job.stderrText();
  // Nothing but (perhaps) the partial image is left beside the old output.
  std::set<std::string> files = filesIn(dir.path());
  files.erase("out.png.partial.exr");
  EXPECT_EQ(files, (std::set<std::string>{"slow.ray", "out.png"}));
}

TEST(Distributed, SigintToMpirunKeepsTheOldOutputAndWritesThePartialImage) {
  SKIP_WITHOUT_MPI();
  TempDir dir;
  std::ofstream(dir.file("slow.ray")) << slowScene();
  const std::string old = "previous image: must survive the interruption byte for byte";
  std::ofstream(dir.file("out.png")) << old;
  ChildProcess job = startJob(2, kSlowRender, dir.path());
  ASSERT_TRUE(job.waitForStderr("rendering", 120)) << job.stderrText();
  auto t0 = Clock::now();
  kill(job.pid(), SIGINT);
  ASSERT_TRUE(job.wait(30));
  double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  std::printf("job stopped %.2f s after SIGINT (exit %d)\n", seconds, job.shellStatus());
  // mpirun passes the interrupt on as SIGTERM (after SIGCONT, about a second later) and
  // exits with its own status for an aborted job.
  EXPECT_NE(job.shellStatus(), 0);
  EXPECT_LT(seconds, 10.0);
  EXPECT_EQ(slurp(dir.file("out.png")), old);
  EXPECT_NE(job.stderrText().find("interrupted; out.png untouched, partial image in out.png.partial.exr"), std::string::npos)
      << job.stderrText();
  EXPECT_EQ(filesIn(dir.path()), (std::set<std::string>{"slow.ray", "out.png", "out.png.partial.exr"}));
  EXPECT_GT(fs::file_size(dir.file("out.png.partial.exr")), 1000u);
}

}  // namespace
