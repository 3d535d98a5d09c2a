#pragma once
/// Carries contact history across a rebuild: each new key looks itself up among the previous sorted
/// keys (binary search) and takes that contact's shear force, rolling moment and flags, and its last step's
/// results (a batch's specimen that is stopped keeps its stress through the others' rebuilds); new contacts
/// start from zero. Keys are global ids, so re-sorting particles never loses history.
#include "kernels/neighbor/contact_list.hpp"
#include "kernels/core/particles.hpp"

namespace dem {

/// gid -> current local index (-1 for unused gids).
IndexView gid_to_local(const Particles& p);
/// The same into `map`, reused where it has the gids' bound of entries.
void gid_to_local(const Particles& p, IndexView& map);

/// A contact list over `keys` with local indices resolved through gid2local and history from `old`. With `buffers`
/// (those the keys were found with), the list is written into their next set, which it then takes; `old` must be
/// the buffers' present list or none of theirs.
ContactList remap_history(const PairKeyView& keys, const ContactList& old, const IndexView& gid2local,
                          bool ball_ball, ListBuffers* buffers = nullptr);

}  // namespace dem
