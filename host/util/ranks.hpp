#pragma once
/// A job spread over MPI ranks (`mpirun -n R triaxdem study|calibrate|diagnose ...`, or `srun`): every rank runs the
/// same command on the same inputs, so every rank reaches each process pool with the same state. At a pool the leader
/// (rank 0) keeps the queue and hands each piece to an idle rank, which runs it in a child process as the local pool
/// would, and sends its result back; once the pool ends, every rank takes in every result, so all go on alike. Only
/// the leader writes files and prints; the other ranks (shadows) compute the same things silently. Results are
/// the local run's, bit for bit, whatever the number of ranks: the pieces are the same code on the same state.
/// Without MPI (a build without it, or a program not started by mpirun or srun) one rank runs everything, as before.
#include <string>

namespace dem {

struct PoolWork;

namespace ranks {

/// Before anything else in main: joins the MPI job when the program was started as one of several ranks. Throws
/// std::runtime_error where this build has no MPI but the environment says mpirun or srun started it as a rank
/// of several: such a job would run every rank's copy in full, into the same folder.
void start(int& argc, char**& argv);
/// After everything else in main (MPI_Finalize where start joined a job).
void stop();
/// Ends every rank at once after an error, with this exit status (MPI_Abort): a leader that fails must not leave the
/// shadows waiting at the next pool.
[[noreturn]] void abort_all(int status);

int rank();
int size();
/// More than one rank: the pools spread their pieces over the ranks.
inline bool spread() { return size() > 1; }
/// The rank that writes files and prints: rank 0, or the only one.
inline bool leader() { return rank() == 0; }
/// The ranks on this rank's node (sharing its cores and memory): 1 without MPI.
int per_node();
/// Whether this build can join an MPI job.
bool built_with_mpi();

/// Sends the terminal's output of the shadows to /dev/null: only the leader prints. Errors still reach the
/// terminal through error_line.
void quiet_shadows();
/// One line on the terminal's error stream, from any rank, prefixed with the rank where several run.
void error_line(const std::string& text);

/// The leader's value of s on every rank (a dated folder's name, which each rank's clock would stamp otherwise).
std::string agree(const std::string& s);
/// Checks that every rank sees `folder` (created by the leader before): the leader writes a token there and each
/// rank reads it back. Throws on every rank, naming the ranks and hosts that cannot, where any cannot (the ranks of
/// a study write their cases there; all of them read a calibration's stored runs there).
void check_shared_folder(const std::string& folder);

/// The pool spread over the ranks (process_pool.hpp's run_pool calls it when spread()): `tries` times at most for a
/// piece whose process was killed (a signal) on its rank, each time on the next idle rank; a piece that exits with a
/// status of its own has failed for good.
void run_pool_on_ranks(const PoolWork& w, const char* what, int tries);

}  // namespace ranks
}  // namespace dem
