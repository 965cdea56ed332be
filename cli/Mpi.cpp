#include "Mpi.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <thread>

#ifdef PARCELSCOPE_MPI
#include <mpi.h>
#endif

namespace parcelscope::cli {

#ifdef PARCELSCOPE_MPI

namespace {
bool started = false;

// Whether an MPI launcher (mpirun, srun) started this process.
bool launched() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"}) {
    if (std::getenv(name)) return true;
  }
  return false;
}

constexpr std::size_t kChunk = std::size_t(1) << 30;  // bytes per message (MPI counts are int)
}  // namespace

MpiSession::MpiSession(int& argc, char**& argv) {
  if (!launched()) return;
  // Worker threads run beside MPI; only the main thread calls it.
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  started = true;
}

MpiSession::~MpiSession() {
  if (!started) return;
  // Ranks done early wait for rank 0 asleep: OpenMPI's finalize waits by
  // spinning, which would take a core from rank 0's generation and writing.
  MPI_Request done;
  MPI_Ibarrier(MPI_COMM_WORLD, &done);
  for (int finished = 0;;) {
    MPI_Test(&done, &finished, MPI_STATUS_IGNORE);
    if (finished) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  MPI_Finalize();
}

int mpiRank() {
  int rank = 0;
  if (started) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

int mpiSize() {
  int size = 1;
  if (started) MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

pipeline::ShardReading rankReading() {
  pipeline::ShardReading reading;
  reading.spatialFilter = true;
  // The extent of every rank's features, and the median of their centres
  // (found on rank 0 from all of them, as one process finds it).
  reading.exchange = [](io::FrameSample& sample) {
    double local[4] = {sample.extent.minX, sample.extent.minY, -sample.extent.maxX, -sample.extent.maxY};
    double all[4];
    MPI_Allreduce(local, all, 4, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
    sample.extent = {all[0], all[1], -all[2], -all[3]};
    const int size = mpiSize(), rank = mpiRank();
    if (sample.centresX.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
      abortRanks("more than 2^31 features in one rank's strip: use more ranks");
    }
    const int mine = static_cast<int>(sample.centresX.size());
    std::vector<int> counts(static_cast<std::size_t>(size)), offsets(static_cast<std::size_t>(size));
    MPI_Gather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::vector<double> xs, ys;
    if (rank == 0) {
      long long total = 0;
      for (int r = 0; r < size; ++r) {
        offsets[r] = static_cast<int>(total);
        total += counts[r];
      }
      if (total > std::numeric_limits<int>::max()) abortRanks("more than 2^31 features: too many for one frame sample");
      xs.resize(static_cast<std::size_t>(total));
      ys.resize(static_cast<std::size_t>(total));
    }
    MPI_Gatherv(sample.centresX.data(), mine, MPI_DOUBLE, xs.data(), counts.data(), offsets.data(), MPI_DOUBLE, 0,
                MPI_COMM_WORLD);
    MPI_Gatherv(sample.centresY.data(), mine, MPI_DOUBLE, ys.data(), counts.data(), offsets.data(), MPI_DOUBLE, 0,
                MPI_COMM_WORLD);
    // -1: no feature anywhere; the median as one process takes it (nth_element at n / 2).
    double median[3] = {-1, 0, 0};
    if (rank == 0 && !xs.empty()) {
      const auto half = static_cast<long>(xs.size() / 2);
      std::nth_element(xs.begin(), xs.begin() + half, xs.end());
      std::nth_element(ys.begin(), ys.begin() + half, ys.end());
      median[0] = 1;
      median[1] = xs[static_cast<std::size_t>(half)];
      median[2] = ys[static_cast<std::size_t>(half)];
    }
    MPI_Bcast(median, 3, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    sample.centresX.clear();
    sample.centresY.clear();
    if (median[0] > 0) {
      sample.centresX.push_back(median[1]);
      sample.centresY.push_back(median[2]);
    }
  };
  return reading;
}

namespace {
// `n` bytes to or from `peer`, in messages of at most kChunk bytes.
void transfer(char* data, std::size_t n, int peer, bool send) {
  for (std::size_t at = 0; at < n; at += kChunk) {
    const int count = static_cast<int>(std::min(kChunk, n - at));
    if (send) {
      MPI_Send(data + at, count, MPI_CHAR, peer, 1, MPI_COMM_WORLD);
    } else {
      MPI_Recv(data + at, count, MPI_CHAR, peer, 1, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    }
  }
}
}  // namespace

void sendPart(const std::string& bytes) {
  unsigned long long n = bytes.size();
  MPI_Send(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, 0, MPI_COMM_WORLD);
  transfer(const_cast<char*>(bytes.data()), bytes.size(), 0, true);
}

void receiveParts(const std::function<void(int rank, std::string bytes)>& take) {
  for (int r = 1, size = mpiSize(); r < size; ++r) {
    unsigned long long n = 0;
    MPI_Recv(&n, 1, MPI_UNSIGNED_LONG_LONG, r, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    std::string bytes(static_cast<std::size_t>(n), '\0');
    transfer(bytes.data(), bytes.size(), r, false);
    take(r, std::move(bytes));
  }
}

void abortRanks(const std::string& message) {
  std::fprintf(stderr, "%s\n", message.c_str());
  std::fflush(stderr);
  if (started) MPI_Abort(MPI_COMM_WORLD, 1);
  std::exit(1);
}

#else

MpiSession::MpiSession(int&, char**&) {}
MpiSession::~MpiSession() = default;
int mpiRank() { return 0; }
int mpiSize() { return 1; }
pipeline::ShardReading rankReading() { return {}; }
void sendPart(const std::string&) {}
void receiveParts(const std::function<void(int rank, std::string bytes)>&) {}
void abortRanks(const std::string& message) {
  std::fprintf(stderr, "%s\n", message.c_str());
  std::exit(1);
}

#endif

}  // namespace parcelscope::cli
