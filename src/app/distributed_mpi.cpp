// The distributed render over MPI (distributed.h). All MPI calls of a rank are made by one
// thread at a time (MPI_THREAD_SERIALIZED): while tiles render, a communication thread per
// rank does them (on rank 0 it serves the tile queue, elsewhere it asks for tiles and sends
// the finished ones); before and after, the main thread. Every wait polls (MPI_Iprobe,
// MPI_Test, a short sleep between), so no rank spins a core while it waits and every wait
// ends on an interrupt; there is no blocking collective before the final MPI_Finalize.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>

#include <fmt/format.h>

#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <mutex>
#include <thread>
#include <type_traits>

#include "app/distributed.h"
#include "core/error.h"

namespace lc::app {

namespace {

using render::RenderResult;
using render::TileGrid;
using render::TileRect;

enum Tag : int {
  kRequest = 101,  // rank -> 0: one tile, please (an int, unused)
  kAssign,         // 0 -> rank: a tile index, or -1 when none is left
  kTile,           // rank -> 0: a rendered tile (packTile)
  kReference,      // rank -> 0: its reference pixels and brute-force statistics
  kText,           // rank -> 0: its statistics (Cluster::gather)
};

// Between polls of an idle wait: short against a tile (tens of milliseconds and more),
// long enough that a waiting thread costs no measurable CPU.
constexpr auto kPollSleep = std::chrono::microseconds(200);

bool isSet(const std::atomic<bool>* flag) { return flag && flag->load(std::memory_order_relaxed); }

// Waits for a non-blocking operation, polling; false when `cancel` is set first (the
// operation is then left pending: the process is about to exit).
bool waitFor(MPI_Request& req, const std::atomic<bool>* cancel) {
  for (;;) {
    int done = 0;
    MPI_Test(&req, &done, MPI_STATUS_IGNORE);
    if (done) return true;
    if (isSet(cancel)) return false;
    std::this_thread::sleep_for(kPollSleep);
  }
}

// Waits for a message from `source` with `tag`, polling; false on cancel.
bool waitForMessage(int source, int tag, MPI_Status& st, const std::atomic<bool>* cancel) {
  for (;;) {
    int flag = 0;
    MPI_Iprobe(source, tag, MPI_COMM_WORLD, &flag, &st);
    if (flag) return true;
    if (isSet(cancel)) return false;
    std::this_thread::sleep_for(kPollSleep);
  }
}

// Sends bytes and waits for the send to complete (so the buffer may go), polling.
bool sendBytes(const void* data, size_t n, int dest, int tag, const std::atomic<bool>* cancel) {
  MPI_Request req;
  MPI_Isend(data, int(n), MPI_BYTE, dest, tag, MPI_COMM_WORLD, &req);
  return waitFor(req, cancel);
}

// Receives the message `st` announced, whatever its size.
std::vector<char> receiveBytes(const MPI_Status& st) {
  int n = 0;
  MPI_Get_count(&st, MPI_BYTE, &n);
  std::vector<char> buf(size_t(std::max(0, n)));
  MPI_Status rs;
  MPI_Recv(buf.data(), n, MPI_BYTE, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, &rs);
  return buf;
}

// A tile on the wire: its index, then per pixel (row by row) the colour, the cut size and
// shadow rays (the --aov layers) and the centre's luminance (for the seams) as floats, then
// its done flags. Exact: the floats are
// copied, not converted.
struct PixelRecord {
  float r, g, b, cut, rays, centre;  // centre: RenderResult::centreLuminance
};

std::vector<char> packTile(int tile, const TileRect& t, const RenderResult& res) {
  const size_t n = size_t(t.x1 - t.x0) * size_t(t.y1 - t.y0);
  std::vector<char> buf(sizeof(int32_t) + n * sizeof(PixelRecord) + n);
  int32_t idx = tile;
  std::memcpy(buf.data(), &idx, sizeof idx);
  char* px = buf.data() + sizeof idx;
  char* done = px + n * sizeof(PixelRecord);
  const int w = res.image.width;
  for (int y = t.y0; y < t.y1; ++y)
    for (int x = t.x0; x < t.x1; ++x) {
      size_t i = size_t(y) * size_t(w) + size_t(x);
      const Color& c = res.image.pixels[i];
      PixelRecord r{c.x, c.y, c.z, res.cutSize[i], i < res.shadowRays.size() ? res.shadowRays[i] : 0.0f,
                    i < res.centreLuminance.size() ? res.centreLuminance[i] : 0.0f};
      std::memcpy(px, &r, sizeof r);
      px += sizeof r;
      // The done flag, and in bit 1 whether adaptive antialiasing re-sampled the pixel.
      *done++ = char(res.done[i] | ((i < res.aaFlagged.size() ? res.aaFlagged[i] : 0) << 1));
    }
  return buf;
}

// Stores a packed tile in the result; false when it does not fit the grid.
bool unpackTile(const std::vector<char>& buf, const TileGrid& grid, RenderResult& res) {
  int32_t idx = -1;
  if (buf.size() < sizeof idx) return false;
  std::memcpy(&idx, buf.data(), sizeof idx);
  if (idx < 0 || idx >= grid.count()) return false;
  const TileRect t = grid.rect(idx);
  const size_t n = size_t(t.x1 - t.x0) * size_t(t.y1 - t.y0);
  if (buf.size() != sizeof idx + n * sizeof(PixelRecord) + n) return false;
  const char* px = buf.data() + sizeof idx;
  const char* done = px + n * sizeof(PixelRecord);
  const int w = res.image.width;
  for (int y = t.y0; y < t.y1; ++y)
    for (int x = t.x0; x < t.x1; ++x) {
      size_t i = size_t(y) * size_t(w) + size_t(x);
      PixelRecord r;
      std::memcpy(&r, px, sizeof r);
      px += sizeof r;
      res.image.pixels[i] = Color(r.r, r.g, r.b);
      res.cutSize[i] = r.cut;
      if (i < res.shadowRays.size()) res.shadowRays[i] = r.rays;
      if (i < res.centreLuminance.size()) res.centreLuminance[i] = r.centre;
      const uint8_t flags = uint8_t(*done++);
      res.done[i] = flags & 1;
      if (i < res.aaFlagged.size()) res.aaFlagged[i] = (flags >> 1) & 1;
    }
  return true;
}

static_assert(std::is_trivially_copyable_v<lightcuts::EvalStats>);

// Reference pixels: rank r computes those with i % size == r.
bool ownsReferenceOf(size_t i, int rank, int size) { return int(i % size_t(size)) == rank; }

// Rank 0: its threads take tiles from the queue (an atomic counter) directly; a
// communication thread hands them to the other ranks on request and stores the tiles they
// send back in the result.
class RootShare final : public render::WorkShare {
 public:
  RootShare(int size, std::atomic<bool>* cancel) : size_(size), cancel_(cancel) {}
  ~RootShare() override { stopComm(); }

  void begin(const TileGrid& grid, RenderResult& result) override {
    grid_ = grid;
    result_ = &result;
    comm_ = std::thread([this] { serve(); });
  }
  int next() override { return isSet(cancel_) ? -1 : take(); }
  void rendered(int, const RenderResult&) override { ++in_; }
  double fractionDone() const override { return grid_.count() ? double(in_.load()) / double(grid_.count()) : 1; }
  void endTiles() override {
    if (comm_.joinable()) comm_.join();
    if (!badTile_.empty()) throw Error(badTile_);
  }
  bool ownsReference(size_t i) const override { return ownsReferenceOf(i, 0, size_); }
  void gatherReference(std::vector<Color>& reference, lightcuts::EvalStats& brute) override {
    for (int k = 1; k < size_; ++k) {
      MPI_Status st;
      if (!waitForMessage(MPI_ANY_SOURCE, kReference, st, cancel_)) return;
      std::vector<char> buf = receiveBytes(st);
      const int src = st.MPI_SOURCE;
      size_t count = 0;
      for (size_t i = 0; i < reference.size(); ++i) count += ownsReferenceOf(i, src, size_);
      if (buf.size() != count * 3 * sizeof(float) + sizeof(lightcuts::EvalStats))
        throw Error(fmt::format("rank {} sent {} bytes of reference pixels for {} pixels", src, buf.size(), count));
      const char* p = buf.data();
      for (size_t i = 0; i < reference.size(); ++i) {
        if (!ownsReferenceOf(i, src, size_)) continue;
        float c[3];
        std::memcpy(c, p, sizeof c);
        p += sizeof c;
        reference[i] = Color(c[0], c[1], c[2]);
      }
      lightcuts::EvalStats s;
      std::memcpy(&s, p, sizeof s);
      brute.add(s);
    }
  }
  bool gathers() const override { return true; }

 private:
  int take() {
    int t = next_.fetch_add(1);
    return t < grid_.count() ? t : -1;
  }

  // Until every tile is in and every rank has been told that none is left.
  void serve() {
    std::vector<bool> told(size_t(size_), false);
    int toldCount = 1;  // rank 0 needs no telling
    while (!(in_.load() == grid_.count() && toldCount == size_)) {
      if (isSet(cancel_) || stop_.load()) return;
      bool busy = false;
      int flag = 0;
      MPI_Status st;
      MPI_Iprobe(MPI_ANY_SOURCE, kRequest, MPI_COMM_WORLD, &flag, &st);
      if (flag) {
        int dummy = 0;
        MPI_Recv(&dummy, 1, MPI_INT, st.MPI_SOURCE, kRequest, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        int t = take();
        if (t < 0 && !told[size_t(st.MPI_SOURCE)]) {
          told[size_t(st.MPI_SOURCE)] = true;
          ++toldCount;
        }
        // Small: sent eagerly, so the blocking call returns at once.
        MPI_Send(&t, 1, MPI_INT, st.MPI_SOURCE, kAssign, MPI_COMM_WORLD);
        busy = true;
      }
      MPI_Iprobe(MPI_ANY_SOURCE, kTile, MPI_COMM_WORLD, &flag, &st);
      if (flag) {
        std::vector<char> buf = receiveBytes(st);
        if (!unpackTile(buf, grid_, *result_)) {
          badTile_ = fmt::format("rank {} sent a tile that does not fit the image ({} bytes)", st.MPI_SOURCE, buf.size());
          return;
        }
        ++in_;
        busy = true;
      }
      if (!busy) std::this_thread::sleep_for(kPollSleep);
    }
  }
  void stopComm() {
    stop_ = true;
    if (comm_.joinable()) comm_.join();
  }

  int size_;
  std::atomic<bool>* cancel_;
  TileGrid grid_;
  RenderResult* result_ = nullptr;
  std::atomic<int> next_{0}, in_{0};
  std::atomic<bool> stop_{false};
  std::string badTile_;
  std::thread comm_;
};

// Ranks 1..K-1: a communication thread keeps one tile ready beyond those the threads wait
// for (one request in flight at a time), and sends rank 0 each tile as it is finished.
class WorkerShare final : public render::WorkShare {
 public:
  WorkerShare(int rank, int size, std::atomic<bool>* cancel) : rank_(rank), size_(size), cancel_(cancel) {}
  ~WorkerShare() override {
    stop_ = true;
    cv_.notify_all();
    if (comm_.joinable()) comm_.join();
  }

  void begin(const TileGrid& grid, RenderResult&) override {
    grid_ = grid;
    comm_ = std::thread([this] { talk(); });
  }
  int next() override {
    std::unique_lock<std::mutex> lock(mu_);
    ++waiting_;
    while (queue_.empty() && !exhausted_ && !isSet(cancel_) && !stop_) cv_.wait_for(lock, std::chrono::milliseconds(50));
    --waiting_;
    if (queue_.empty()) return -1;
    int t = queue_.front();
    queue_.pop_front();
    return t;
  }
  void rendered(int tile, const RenderResult& result) override {
    std::vector<char> buf = packTile(tile, grid_.rect(tile), result);
    std::lock_guard<std::mutex> lock(mu_);
    outbox_.push_back(std::move(buf));
  }
  double fractionDone() const override { return 0; }  // rank 0 reports progress
  void endTiles() override {
    tilesEnded_ = true;
    if (comm_.joinable()) comm_.join();
  }
  bool ownsReference(size_t i) const override { return ownsReferenceOf(i, rank_, size_); }
  void gatherReference(std::vector<Color>& reference, lightcuts::EvalStats& brute) override {
    std::vector<char> buf;
    for (size_t i = 0; i < reference.size(); ++i) {
      if (!ownsReference(i)) continue;
      float c[3] = {reference[i].x, reference[i].y, reference[i].z};
      buf.insert(buf.end(), reinterpret_cast<const char*>(c), reinterpret_cast<const char*>(c) + sizeof c);
    }
    buf.insert(buf.end(), reinterpret_cast<const char*>(&brute), reinterpret_cast<const char*>(&brute) + sizeof brute);
    sendBytes(buf.data(), buf.size(), 0, kReference, cancel_);
  }
  bool gathers() const override { return false; }

 private:
  void talk() {
    bool requested = false;
    std::deque<std::pair<MPI_Request, std::vector<char>>> sending;
    for (;;) {
      if (isSet(cancel_) || stop_) return;
      bool busy = false;
      bool ask = false;
      std::deque<std::vector<char>> out;
      {
        std::lock_guard<std::mutex> lock(mu_);
        ask = !requested && !exhausted_ && int(queue_.size()) < waiting_ + 1;
        out.swap(outbox_);
      }
      if (ask) {
        int one = 1;
        MPI_Send(&one, 1, MPI_INT, 0, kRequest, MPI_COMM_WORLD);
        requested = true;
        busy = true;
      }
      int flag = 0;
      MPI_Status st;
      MPI_Iprobe(0, kAssign, MPI_COMM_WORLD, &flag, &st);
      if (flag) {
        int t = -1;
        MPI_Recv(&t, 1, MPI_INT, 0, kAssign, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        requested = false;
        {
          std::lock_guard<std::mutex> lock(mu_);
          if (t < 0)
            exhausted_ = true;
          else
            queue_.push_back(t);
        }
        cv_.notify_all();
        busy = true;
      }
      for (auto& b : out) {
        sending.emplace_back();
        sending.back().second = std::move(b);
        MPI_Isend(sending.back().second.data(), int(sending.back().second.size()), MPI_BYTE, 0, kTile, MPI_COMM_WORLD,
                  &sending.back().first);
        busy = true;
      }
      while (!sending.empty()) {
        int done = 0;
        MPI_Test(&sending.front().first, &done, MPI_STATUS_IGNORE);
        if (!done) break;
        sending.pop_front();
      }
      if (tilesEnded_ && sending.empty()) {
        std::lock_guard<std::mutex> lock(mu_);
        if (exhausted_ && outbox_.empty()) return;
      }
      if (!busy) std::this_thread::sleep_for(kPollSleep);
    }
  }

  int rank_, size_;
  std::atomic<bool>* cancel_;
  TileGrid grid_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<int> queue_;
  std::deque<std::vector<char>> outbox_;
  bool exhausted_ = false;
  int waiting_ = 0;
  std::atomic<bool> tilesEnded_{false}, stop_{false};
  std::thread comm_;
};

class MpiCluster final : public Cluster {
 public:
  MpiCluster() {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
    if (provided < MPI_THREAD_SERIALIZED)
      throw Error("MPI: this MPI library cannot be called from a thread other than the main one "
                  "(MPI_THREAD_SERIALIZED)");
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    char name[MPI_MAX_PROCESSOR_NAME] = {};
    int len = 0;
    MPI_Get_processor_name(name, &len);
    host_.assign(name, size_t(std::max(0, len)));
  }
  // Without finish(), MPI is left as it is: a failing rank must not wait in MPI_Finalize for
  // ranks that still render; its exit ends the job.
  ~MpiCluster() override = default;

  int rank() const override { return rank_; }
  int size() const override { return size_; }
  std::string host() const override { return host_; }
  std::unique_ptr<render::WorkShare> workShare(std::atomic<bool>* cancel) override {
    if (rank_ == 0) return std::make_unique<RootShare>(size_, cancel);
    return std::make_unique<WorkerShare>(rank_, size_, cancel);
  }
  std::vector<std::string> gather(const std::string& text, std::atomic<bool>* cancel) override {
    if (rank_ != 0) {
      sendBytes(text.data(), text.size(), 0, kText, cancel);
      return {};
    }
    std::vector<std::string> all(static_cast<size_t>(size_));
    all[0] = text;
    for (int k = 1; k < size_; ++k) {
      MPI_Status st;
      if (!waitForMessage(MPI_ANY_SOURCE, kText, st, cancel)) return {};
      std::vector<char> buf = receiveBytes(st);
      all[size_t(st.MPI_SOURCE)].assign(buf.begin(), buf.end());
    }
    return all;
  }
  void finish() override {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
  }

 private:
  int rank_ = 0, size_ = 1;
  std::string host_;
};

bool startedByMpiLauncher() {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"}) {
    const char* v = std::getenv(var);
    if (v && *v) return true;
  }
  return false;
}

}  // namespace

std::unique_ptr<Cluster> joinCluster() {
  if (!startedByMpiLauncher()) return nullptr;
  return std::make_unique<MpiCluster>();
}

bool builtWithMpi() { return true; }

}  // namespace lc::app
