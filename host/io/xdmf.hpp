#pragma once
/// The ParaView index of a run's snapshots (snapshots.xdmf): XDMF 3 temporal collections of the particles and of
/// the membrane surface, whose data stay in the snapshot HDF5 files.
#include <string>
#include <utility>
#include <vector>

namespace dem::io {

/// One snapshot file as the index sees it.
struct XdmfStep {
  std::string file;  ///< relative to the index, so that the output folder can be moved or copied as a whole
  long step = 0;
  double time = 0;
  long particles = 0;
  long surface_nodes = 0, surface_triangles = 0;
  std::vector<std::pair<std::string, std::string>> scalars;  ///< per-particle scalars: the name shown, its dataset
};

/// The whole index. Empty grids are left out: the XDMF readers of ParaView fail on a zero-sized DataItem.
std::string xdmf_document(const std::vector<XdmfStep>& steps);

}  // namespace dem::io
