#pragma once
/// What the pool over ranks (rank_pool.cpp) shares with the rank's own state (ranks.cpp); MPI builds only.
#include <mpi.h>

namespace dem::ranks::detail {

/// Waits for a request with a short sleep between tests: MPI's own wait polls a core flat out, which a rank waiting
/// for hours (the leader while the others run, a shadow at a pool's end) would take from those that run.
MPI_Status idle_wait(MPI_Request& req);
/// A message from `source` (or any) with `tag`, received once it has come; its status says from where.
MPI_Status idle_recv(void* buf, int count, MPI_Datatype type, int source, int tag);
/// In a piece's child: a process of its own, as the local pool's children are. It writes what they write, and a
/// program it starts does not take itself for a rank.
void become_single_process();
/// A rank was taken for dead: MPI_Finalize, which would wait for it for ever, is left out at the end.
void note_lost_rank();

}  // namespace dem::ranks::detail
