#include "host/io/xdmf.hpp"

#include <charconv>

namespace dem::io {

namespace {

std::string xml_escape(const std::string& text) {
  std::string out;
  for (const char c : text)
    out += c == '&' ? "&amp;" : c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '"' ? "&quot;" : std::string(1, c);
  return out;
}

/// NumberType/Precision pair of an XDMF DataItem.
constexpr const char* kF64 = "NumberType=\"Float\" Precision=\"8\"";
constexpr const char* kU32 = "NumberType=\"UInt\" Precision=\"4\"";
constexpr const char* kI32 = "NumberType=\"Int\" Precision=\"4\"";

/// The file name is relative, so the output folder can be moved or copied as a whole.
std::string data_item(const std::string& file, const std::string& dataset, long rows, int cols, const char* type) {
  const std::string dims = std::to_string(rows) + (cols > 1 ? " " + std::to_string(cols) : "");
  return "<DataItem Format=\"HDF\" Dimensions=\"" + dims + "\" " + type + ">" + xml_escape(file + ":/" + dataset) +
         "</DataItem>";
}

std::string node_attribute(const std::string& name, const std::string& item, bool vector) {
  return "      <Attribute Name=\"" + xml_escape(name) + "\" AttributeType=\"" + (vector ? "Vector" : "Scalar") +
         "\" Center=\"Node\">" + item + "</Attribute>\n";
}

/// Opens a time step's grid. Time is the shortest text that reads back as the same double.
std::string grid_head(long step, double time, const std::string& topology, long cells, const std::string& conn,
                      const std::string& nodes) {
  char value[32];
  char* end = std::to_chars(value, value + sizeof value, time).ptr;
  return "    <Grid Name=\"step_" + std::to_string(step) + "\" GridType=\"Uniform\">\n      <Time Value=\"" +
         std::string(value, end) + "\"/>\n      <Topology " + topology + " NumberOfElements=\"" +
         std::to_string(cells) + "\">" + conn + "</Topology>\n      <Geometry GeometryType=\"XYZ\">" + nodes +
         "</Geometry>\n";
}

std::string particle_grid(const XdmfStep& s) {
  const std::string& file = s.file;
  const long n = s.particles;
  std::string grid = grid_head(s.step, s.time, "TopologyType=\"Polyvertex\" NodesPerElement=\"1\"", n,
                               data_item(file, "cells", n, 1, kI32), data_item(file, "x", n, 3, kF64)) +
                     node_attribute("radius", data_item(file, "radius", n, 1, kF64), false) +
                     node_attribute("v", data_item(file, "v", n, 3, kF64), true) +
                     node_attribute("w", data_item(file, "w", n, 3, kF64), true) +
                     node_attribute("gid", data_item(file, "gid", n, 1, kU32), false) +
                     node_attribute("specimen", data_item(file, "specimen", n, 1, kI32), false);
  for (const auto& [name, dataset] : s.scalars)
    grid += node_attribute(name, data_item(file, dataset, n, 1, kF64), false);
  return grid + "    </Grid>\n";
}

std::string surface_grid(const XdmfStep& s) {
  return grid_head(s.step, s.time, "TopologyType=\"Triangle\"", s.surface_triangles,
                   data_item(s.file, "surface/triangles", s.surface_triangles, 3, kI32),
                   data_item(s.file, "surface/nodes", s.surface_nodes, 3, kF64)) +
         "    </Grid>\n";
}

std::string temporal_collection(const char* name, const std::string& grids) {
  if (grids.empty()) return "";
  return std::string("  <Grid Name=\"") + name + "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n" + grids +
         "  </Grid>\n";
}

}  // namespace

std::string xdmf_document(const std::vector<XdmfStep>& steps) {
  std::string particles, surface;
  for (const XdmfStep& s : steps) {
    if (s.particles > 0) particles += particle_grid(s);
    if (s.surface_triangles > 0) surface += surface_grid(s);
  }
  return "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n" + temporal_collection("particles", particles) +
         temporal_collection("surface", surface) + "</Domain>\n</Xdmf>\n";
}

}  // namespace dem::io
