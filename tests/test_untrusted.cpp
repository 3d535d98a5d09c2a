/// Files edited by hand or damaged on the way, as users pass checkpoints and snapshots between machines: each
/// is refused with the file, the dataset, the row and the allowed range, before anything of the run changes.
/// The files are real ones written by triaxdem, then edited through the HDF5 C API as a user with h5py would.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "host/engine/builder.hpp"
#include "host/engine/checkpoint.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/engine/micro.hpp"
#include "host/engine/simulation.hpp"
#include "host/triax/triaxial_state.hpp"
#include "test_util.hpp"

using namespace dem;

namespace {

/// Twelve balls in a box with walls, run until they touch the floor and each other: a state with ball-ball and
/// ball-wall contacts, as a checkpoint of a real run holds.
std::unique_ptr<Simulation> settled_box() {
  std::vector<BallSpec> balls;
  for (int k = 0; k < 12; ++k) {
    BallSpec b;
    b.radius = 1e-3;
    b.density = 2500;
    b.x = Vec3(1.1e-3 + 2.05e-3 * (k % 3), 1.1e-3 + 2.05e-3 * ((k / 3) % 2), 1.02e-3 + 2.01e-3 * (k / 6));
    balls.push_back(b);
  }
  std::vector<WallSpec> walls(1);
  walls[0].point = Vec3(0, 0, 0);
  walls[0].normal = Vec3(0, 0, 1);
  SimParams prm;
  prm.skin = 0.2e-3;
  prm.integ.alpha = 0.7;
  prm.integ.gravity = Vec3(0, 0, -9.81);
  auto sim = std::make_unique<Simulation>(make_particles(balls), make_walls(walls), FacetMesh(),
                                          std::vector<ContactParams>{test::law(1e8, 1.5, 0.3, 0.05)}, 1, prm);
  sim->set_dt(0.2 * sim->critical_dt());
  sim->run(3000);
  return sim;
}

/// Overwrites the first value of a row of a dataset in place, as an edit with h5py would.
template <class T>
void poke(const std::string& file, const std::string& dataset, hsize_t row, T value, hid_t type) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0) << file;
  const hid_t set = H5Dopen2(f, dataset.c_str(), H5P_DEFAULT);
  ASSERT_GE(set, 0) << dataset;
  const hid_t space = H5Dget_space(set);
  const hsize_t one = 1, at[2] = {row, 0};  // the row's first value, in a vector or a table
  ASSERT_GE(H5Sselect_elements(space, H5S_SELECT_SET, 1, at), 0);
  const hid_t mem = H5Screate_simple(1, &one, nullptr);
  ASSERT_GE(H5Dwrite(set, type, mem, space, H5P_DEFAULT, &value), 0);
  H5Sclose(mem);
  H5Sclose(space);
  H5Dclose(set);
  H5Fclose(f);
}

/// Replaces a dataset by one of another shape (its values all `fill`): dims as given, nothing else checked.
void replace(const std::string& file, const std::string& dataset, const std::vector<hsize_t>& dims, double fill,
             bool write = true) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0) << file;
  H5Ldelete(f, dataset.c_str(), H5P_DEFAULT);
  const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
  const hid_t set = H5Dcreate2(f, dataset.c_str(), H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(set, 0) << dataset;
  if (write) {
    hsize_t n = 1;
    for (hsize_t d : dims) n *= d;
    const std::vector<double> v(n, fill);
    H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  }
  H5Dclose(set);
  H5Sclose(space);
  H5Fclose(f);
}

/// Replaces the root attribute `format` by `text`: one string (count 0), or an array of `count` of them.
void replace_format(const std::string& file, const std::string& text, hsize_t count) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0) << file;
  H5Adelete(f, "format");
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, text.size() + 1);
  const hid_t space = count == 0 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &count, nullptr);
  const hid_t attr = H5Acreate2(f, "format", type, space, H5P_DEFAULT, H5P_DEFAULT);
  std::vector<char> values;
  for (hsize_t k = 0; k < std::max<hsize_t>(count, 1); ++k)
    values.insert(values.end(), text.c_str(), text.c_str() + text.size() + 1);
  H5Awrite(attr, type, values.data());
  H5Aclose(attr);
  H5Sclose(space);
  H5Tclose(type);
  H5Fclose(f);
}

/// Reads a checkpoint, edits it in memory and writes it again, sealed: what an editor who also recomputes the
/// checksum, or a faulty writer, produces. The checks of the values must catch what the checksum no longer can.
void edit_sealed(const std::string& path, const std::function<void(Checkpoint&)>& edit) {
  Checkpoint c = read_checkpoint(path);
  edit(c);
  write_checkpoint(path, c);
}

class Untrusted : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = test::scratch_dir(std::string("untrusted/") + info->name());
  }
  /// A checkpoint of the settled box, written by triaxdem.
  std::string checkpoint() {
    sim_ = settled_box();
    const std::string path = (dir_ / "checkpoint.h5").string();
    write_checkpoint(path, checkpoint_of("run", *sim_, nullptr));
    return path;
  }
  /// The error of reading the checkpoint and restoring it into the same simulation; "" if both pass.
  std::string resume_error(const std::string& path) {
    const SimState before = sim_->state();
    try {
      resume_from(read_checkpoint(path), *sim_, nullptr);
    } catch (const std::exception& e) {
      const SimState after = sim_->state();
      EXPECT_EQ(after.x, before.x) << "a refused checkpoint changed the simulation";
      EXPECT_EQ(after.step, before.step);
      return e.what();
    }
    return "";
  }
  /// Each edit, made behind a valid checksum on a fresh checkpoint, must be refused with its message.
  using SealedEdit = std::pair<std::function<void(Checkpoint&)>, std::string>;
  void expect_refused(const std::vector<SealedEdit>& edits) {
    for (const auto& [edit, expected] : edits) {
      const std::string path = checkpoint();
      edit_sealed(path, edit);
      const std::string got = resume_error(path);
      EXPECT_NE(got.find(expected), std::string::npos) << got;
    }
  }
  std::filesystem::path dir_;
  std::unique_ptr<Simulation> sim_;
};

}  // namespace

// The file as written resumes: the edits below are what makes each case fail.
TEST_F(Untrusted, AnUneditedCheckpointResumes) {
  const std::string path = checkpoint();
  EXPECT_EQ(resume_error(path), "");
  EXPECT_GT(sim_->ball_contacts().n, 0) << "the state has ball-ball contacts to check";
  EXPECT_GT(sim_->wall_contacts().n, 0) << "and ball-wall contacts";
}

// A dataset of rank 8 where a vector is expected: the reader wrote one extent per dimension into a 2-element
// array before it looked at the rank (an out-of-bounds write on the stack, which ASan reports).
TEST_F(Untrusted, ADatasetOfRankEightIsRefusedBeforeItsExtentsAreRead) {
  const std::string path = checkpoint();
  replace(path, "/step", {2, 2, 2, 2, 2, 2, 2, 2}, 1);
  const std::string e = resume_error(path);
  EXPECT_NE(e.find(path), std::string::npos) << e;
  EXPECT_NE(e.find("'/step'"), std::string::npos) << e;
  EXPECT_NE(e.find("rank 8"), std::string::npos) << e;
}


// An edit with h5py leaves the checksum behind: the file is refused as edited or damaged.
TEST_F(Untrusted, AnEditedCheckpointFailsItsChecksum) {
  const std::string path = checkpoint();
  poke(path, "/x", 4, 1e-3, H5T_NATIVE_DOUBLE);
  const std::string e = resume_error(path);
  EXPECT_NE(e.find("the checkpoint was edited or damaged after triaxdem wrote it"), std::string::npos) << e;
}

// Edits behind a valid checksum, each refused at --resume with the array, the row and the allowed range; the
// simulation is left as it was (resume_error checks it).
TEST_F(Untrusted, EditedIndicesInACheckpointAreRefusedWithTheRow) {
  const std::vector<SealedEdit> edits{
      {[](Checkpoint& c) { c.sim.gid[3] = 99999999; }, "state: gid, row 3: 99999999 (allowed: 0 to 11)"},
      {[](Checkpoint& c) { c.sim.gid[3] = c.sim.gid[0]; }, "given twice"},
      {[](Checkpoint& c) { c.sim.material[5] = 7; }, "state: material, row 5: 7 (allowed: 0 to 0)"},
      {[](Checkpoint& c) { c.sim.material[5] = -1; }, "state: material, row 5: -1"},
      {[](Checkpoint& c) { c.sim.balls.i[0] = 99999; }, "state: the ball-ball contacts: i, j, row 0"},
      {[](Checkpoint& c) { c.sim.balls.j[0] = -5; }, "state: the ball-ball contacts: i, j, row 0"},
      {[](Checkpoint& c) { c.sim.walls.j[0] = 42; }, "state: the ball-wall contacts: i, j, row 0"},
      {[](Checkpoint& c) { c.sim.walls.key[0] = (42ull << 32) | 1; }, "names object 42 (allowed: below 1)"},
      {[](Checkpoint& c) { c.sim.balls.key[0] = 0; }, "the ball-ball contacts: key, row 0"},
      {[](Checkpoint& c) { c.sim.step = -1000000000000000L; }, "state: step, row 0"},
  };
  expect_refused(edits);
}

// Non-finite values where the run divides or integrates by them, behind a valid checksum.
TEST_F(Untrusted, NonFiniteValuesInACheckpointAreRefused) {
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<SealedEdit> edits{
      {[](Checkpoint& c) { c.sim.x[3 * 4 + 1] = std::nan(""); }, "a particle vector, row 4"},
      {[](Checkpoint& c) { c.sim.radius[2] = 0; }, "radius, row 2: not a finite positive number"},
      {[&](Checkpoint& c) { c.sim.dt = inf; }, "dt, row 0"},
      {[&](Checkpoint& c) { c.sim.balls.fs[3 * 1] = -inf; }, "the ball-ball contacts history, row 1"}};
  expect_refused(edits);
}

// A checkpoint of another config, of another format version, or whose arrays disagree with its counts.
TEST_F(Untrusted, CheckpointsOfAnotherConfigOrVersionAreRefused) {
  const std::string path = checkpoint();
  edit_sealed(path, [](Checkpoint& c) { c.config = "0123456789abcdef"; });
  try {
    resume_checkpoint(path, "run", "fedcba9876543210");
    ADD_FAILURE() << "resumed with another config";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("written with another config (fingerprint 0123456789abcdef, this config "
                                         "fedcba9876543210)"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(resume_checkpoint(path, "run", "0123456789abcdef"));
  replace_format(path, "triaxdem checkpoint 1", 0);
  const std::string e = resume_error(path);
  EXPECT_NE(e.find("checkpoint format 'triaxdem checkpoint 1', this triaxdem reads 'triaxdem checkpoint 2'"),
            std::string::npos) << e;
}

// Shapes and sizes the reader must check before it allocates or HDF5 writes: a dataset declared with four
// billion rows and nothing stored, floats where indices belong, a string attribute holding an array.
TEST_F(Untrusted, DeclaredSizesTypesAndAttributeShapesAreChecked) {
  {
    const std::string path = checkpoint();
    replace(path, "/x", {4000000000ull, 3}, 0, false);
    const std::string e = resume_error(path);
    EXPECT_NE(e.find("dataset '/x' declares 4000000000 rows, more than a file of"), std::string::npos) << e;
  }
  {
    const std::string path = checkpoint();
    replace(path, "/gid", {12}, 1.5);
    const std::string e = resume_error(path);
    EXPECT_NE(e.find("dataset '/gid' holds floating-point numbers (allowed: integers)"), std::string::npos) << e;
  }
  {
    const std::string path = checkpoint();
    replace_format(path, std::string(63, 'x'), 4);
    const std::string e = resume_error(path);
    EXPECT_NE(e.find("attribute 'format' of '/' is not a single value"), std::string::npos) << e;
  }
}

namespace {
/// A snapshot of three balls in a row on a membrane patch, with two ball-ball contacts and one membrane contact,
/// as the triaxial job writes it at a micro record.
std::string snapshot_file(const std::filesystem::path& dir) {
  io::Snapshot s;
  s.step = 100;
  s.label = "shear eps_a=1%";
  for (int i = 0; i < 3; ++i) {
    s.x.insert(s.x.end(), {2e-3 * i, 0.0, 0.0});
    s.v.insert(s.v.end(), {0.0, 0.0, 0.0});
    s.w.insert(s.w.end(), {0.0, 0.0, 0.0});
    s.radius.push_back(1e-3);
    s.gid.push_back(static_cast<std::uint32_t>(i));
    s.specimen.push_back(0);
  }
  io::SurfaceSnapshot surface;
  surface.nodes = {0, -1e-3, 0, 4e-3, -1e-3, 0, 0, -1e-3, 1e-3};
  surface.triangles = {0, 1, 2};
  io::ContactTable c;
  c.a = {0, 1, 2};
  c.b = {1, 2, -1};
  c.boundary = {0, 0, 2};
  for (int k = 0; k < 3; ++k) {
    c.fn.push_back(1.0);
    c.normal.insert(c.normal.end(), {1.0, 0.0, 0.0});
    c.point.insert(c.point.end(), {1e-3 + 2e-3 * k, 0.0, 0.0});
    c.branch.insert(c.branch.end(), {2e-3, 0.0, 0.0});
    c.ft.insert(c.ft.end(), {0.0, 0.1, 0.0});
  }
  io::Output out((dir / "run").string());
  out.write_snapshot(s, &surface, &c);
  return (dir / "run" / "snap_000000100.h5").string();
}

/// The error of reading a snapshot and building its contact set, as `triaxdem micro` does; "" if both pass.
std::string micro_error(const std::string& path) {
  try {
    contact_set(io::read_snapshot(path), path);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}
}  // namespace

// `triaxdem micro` reads snapshots as they come: contact and triangle indices, gids used as row indices and the
// lengths of the contact arrays are checked before they index anything.
TEST_F(Untrusted, EditedSnapshotsAreRefusedBeforeMicroUsesThem) {
  EXPECT_EQ(micro_error(snapshot_file(dir_ / "clean")), "");
  struct Edit {
    std::string dataset;
    hsize_t row;
    long long value;
    std::string expected;
  };
  const std::vector<Edit> edits{
      {"/contacts/b", 0, -1, "/contacts, row 0: boundary 0 with b = -1"},
      {"/contacts/a", 1, 3, "/contacts, row 1: a ball that is not in the file"},
      {"/contacts/boundary", 2, 7, "/contacts, row 2: boundary 7"},
      {"/surface/triangles", 0, 9, "/surface/triangles, row 0: node 9 (allowed: 0 to 2)"},
      {"/gid", 1, 5, "/gid, row 1: 5 (allowed: 0 to 2)"},
      {"/gid", 1, 0, "/gid, row 1: 0 given twice"},
  };
  int k = 0;
  for (const Edit& e : edits) {
    const std::string path = snapshot_file(dir_ / std::to_string(k++));
    poke(path, e.dataset, e.row, static_cast<int>(e.value), e.dataset == "/gid" ? H5T_NATIVE_UINT32 : H5T_NATIVE_INT);
    const std::string got = micro_error(path);
    EXPECT_NE(got.find(e.expected), std::string::npos) << e.dataset << " = " << e.value << ": " << got;
  }
  const std::string shorter = snapshot_file(dir_ / "short");
  replace(shorter, "/contacts/branch", {2, 3}, 0.0);
  EXPECT_NE(micro_error(shorter).find("/contacts datasets of unequal length"), std::string::npos) << micro_error(shorter);
}

// A triaxial checkpoint's stage values drive its loops: a snapshot index past the four snapshots indexed an array
// past its end, a step of -1e15 started an almost endless loop, and records not a multiple of their count were cut.
TEST_F(Untrusted, TriaxialStageValuesAreCheckedBeforeTheRunChanges) {
  sim_ = settled_box();
  Stage st;
  st.shear = true;
  st.step = 10;
  st.h0 = st.v0 = st.v0_envelope = 1e-6;
  st.void_ratio = 0.7;
  TriaxialResult res;
  res.records.resize(3);
  const std::string path = (dir_ / "triaxial.h5").string();
  struct Case {
    int row;
    double value;
    std::string expected;
  };
  for (const Case& c : std::vector<Case>{{8, -1, "row 8 (next_snap) = -1"},
                                         {8, 4.5, "row 8 (next_snap) = 4.5"},
                                         {1, -1e15, "row 1 (step) = -1"},
                                         {0, 0.5, "row 0 (shear) = 0.5"},
                                         {3, 0, "row 3 (v0) = 0"}}) {
    save_triaxial(path, *sim_, nullptr, st, res);
    edit_sealed(path, [&](Checkpoint& k) { k.numbers.at("stage").at(static_cast<std::size_t>(c.row)) = c.value; });
    Stage got;
    TriaxialResult out;
    try {
      restore_triaxial(read_checkpoint(path), path, *sim_, nullptr, got, out);
      ADD_FAILURE() << "accepted stage row " << c.row << " = " << c.value;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path + ": number_stage, " + c.expected), std::string::npos) << e.what();
    }
  }
  save_triaxial(path, *sim_, nullptr, st, res);
  edit_sealed(path, [](Checkpoint& k) { k.numbers.at("records").resize(3 * 19 - 1); });
  Stage got;
  TriaxialResult out;
  try {
    restore_triaxial(read_checkpoint(path), path, *sim_, nullptr, got, out);
    ADD_FAILURE() << "accepted 56 record values";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("number_records has 56 values (allowed: 19 per record)"), std::string::npos)
        << e.what();
  }
}
