#include "host/util/ranks.hpp"

#include <fcntl.h>
#include <unistd.h>


#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#ifdef TRIAXDEM_HAVE_MPI
#include "host/util/ranks_mpi.hpp"
#endif

namespace dem::ranks {

namespace {

int my_rank = 0;
int my_size = 1;
int node_size = 1;
#ifdef TRIAXDEM_HAVE_MPI
bool joined = false;       // MPI_Init was called here
bool lost_a_rank = false;  // a rank was taken for dead: MPI_Finalize would wait for it for ever
#endif
int terminal_err = 2;      // the terminal's error stream, kept where quiet_shadows sends fd 2 elsewhere
// Set in the environment of a piece's child process: a program it starts is a job of its own, not a rank.
constexpr const char* kChildMark = "TRIAXDEM_RANK_CHILD";

/// The number of ranks mpirun (Open MPI; MPICH's Hydra: PMI_SIZE) or srun (its step's task count: a batch
/// script's own shell is no step of srun's) says this process is one of; 1 when none.
int ranks_from_environment() {
  if (std::getenv(kChildMark)) return 1;
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "SLURM_STEP_NUM_TASKS"}) {
    if (const char* s = std::getenv(v)) {
      const int n = std::atoi(s);
      if (n > 1) return n;
    }
  }
  return 1;
}

}  // namespace

bool built_with_mpi() {
#ifdef TRIAXDEM_HAVE_MPI
  return true;
#else
  return false;
#endif
}

int rank() { return my_rank; }
int per_node() { return node_size; }
int size() { return my_size; }

void start(int& argc, char**& argv) {
  const int n = ranks_from_environment();
  if (n <= 1) return;
#ifdef TRIAXDEM_HAVE_MPI
  MPI_Init(&argc, &argv);
  joined = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &my_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &my_size);
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, my_rank, MPI_INFO_NULL, &node);
  MPI_Comm_size(node, &node_size);
  MPI_Comm_free(&node);
#else
  (void)argc;
  (void)argv;
  throw std::runtime_error("started as one of " + std::to_string(n) +
                           " ranks (mpirun or srun), but this triaxdem was built without MPI: each rank would run "
                           "the whole job into the same folder. Install libopenmpi-dev and openmpi-bin and rebuild "
                           "(cmake finds MPI by itself), or run the command without mpirun");
#endif
}

void stop() {
#ifdef TRIAXDEM_HAVE_MPI
  if (joined && !lost_a_rank) MPI_Finalize();
  joined = false;
#endif
}

void abort_all(int status) {
#ifdef TRIAXDEM_HAVE_MPI
  if (joined) MPI_Abort(MPI_COMM_WORLD, status);
#endif
  std::exit(status);
}

void quiet_shadows() {
  if (leader()) return;
  std::fflush(nullptr);
  terminal_err = ::dup(2);
  const int null = ::open("/dev/null", O_WRONLY);
  if (null < 0) return;
  ::dup2(null, 1);
  ::dup2(null, 2);
  ::close(null);
}

void error_line(const std::string& text) {
  const std::string line = (spread() ? "[rank " + std::to_string(my_rank) + "] " : std::string()) + text + "\n";
  if (::write(terminal_err, line.data(), line.size()) < 0) return;
}

#ifdef TRIAXDEM_HAVE_MPI

namespace detail {

MPI_Status idle_wait(MPI_Request& req) {
  MPI_Status st;
  for (int done = 0;;) {
    MPI_Test(&req, &done, &st);
    if (done) return st;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

MPI_Status idle_recv(void* buf, int count, MPI_Datatype type, int source, int tag) {
  MPI_Request req;
  MPI_Irecv(buf, count, type, source, tag, MPI_COMM_WORLD, &req);
  return idle_wait(req);
}

void become_single_process() {
  my_rank = 0;
  my_size = node_size = 1;
  ::setenv(kChildMark, "1", 1);
}

void note_lost_rank() { lost_a_rank = true; }

}  // namespace detail

namespace {

using detail::idle_wait;

std::vector<char> bcast_bytes(std::vector<char> v) {
  long n = static_cast<long>(v.size());
  MPI_Request req;
  MPI_Ibcast(&n, 1, MPI_LONG, 0, MPI_COMM_WORLD, &req);
  idle_wait(req);
  v.resize(static_cast<std::size_t>(n));
  if (n > 0) {
    MPI_Ibcast(v.data(), static_cast<int>(n), MPI_CHAR, 0, MPI_COMM_WORLD, &req);
    idle_wait(req);
  }
  return v;
}


}  // namespace

std::string agree(const std::string& s) {
  if (!spread()) return s;
  const std::vector<char> v = bcast_bytes(std::vector<char>(s.begin(), s.end()));
  return std::string(v.begin(), v.end());
}

void check_shared_folder(const std::string& folder) {
  if (!spread()) return;
  const std::string token_file = folder + "/.triaxdem_ranks_probe";
  std::string token;
  if (leader()) {
    token = std::to_string(std::random_device{}()) + "-" + std::to_string(::getpid());
    std::ofstream(token_file) << token;
  }
  token = agree(token);
  std::string seen;
  std::getline(std::ifstream(token_file), seen);
  char host[256] = "?";
  ::gethostname(host, sizeof host - 1);
  const std::string mine = seen == token ? std::string() : std::string(host);
  // Each rank's host where it cannot read the token, gathered at the leader and spread to all.
  std::vector<char> name(256, 0);
  std::memcpy(name.data(), mine.data(), std::min<std::size_t>(mine.size(), 255));
  std::vector<char> all(name.size() * static_cast<std::size_t>(my_size));
  MPI_Allgather(name.data(), 256, MPI_CHAR, all.data(), 256, MPI_CHAR, MPI_COMM_WORLD);
  std::string blind;
  for (int r = 0; r < my_size; ++r) {
    const char* h = all.data() + 256 * r;
    if (*h) blind += (blind.empty() ? "" : ", ") + ("rank " + std::to_string(r) + " on " + h);
  }
  MPI_Request req;
  MPI_Ibarrier(MPI_COMM_WORLD, &req);
  detail::idle_wait(req);
  if (leader()) std::remove(token_file.c_str());
  if (!blind.empty())
    throw std::runtime_error("the output folder " + folder + " is not seen by every rank (" + blind +
                             "): the ranks need one shared file system for the output (put -o on it)");
}

#else

std::string agree(const std::string& s) { return s; }
void check_shared_folder(const std::string&) {}

#endif

}  // namespace dem::ranks
