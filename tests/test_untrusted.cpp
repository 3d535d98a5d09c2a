/// Files edited by hand or damaged on the way, as users pass checkpoints and snapshots between machines: each
/// is refused with the file, the dataset, the row and the allowed range, before anything of the run changes.
/// The files are real ones written by triaxdem, then edited through the HDF5 C API as a user with h5py would.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

#include "host/builder.hpp"
#include "host/checkpoint.hpp"
#include "host/simulation.hpp"
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

/// Overwrites one element of an integer or double dataset in place, as an edit with h5py would.
template <class T>
void poke(const std::string& file, const std::string& dataset, hsize_t row, T value, hid_t type) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0) << file;
  const hid_t set = H5Dopen2(f, dataset.c_str(), H5P_DEFAULT);
  ASSERT_GE(set, 0) << dataset;
  const hid_t space = H5Dget_space(set);
  const hsize_t one = 1;
  ASSERT_GE(H5Sselect_elements(space, H5S_SELECT_SET, 1, &row), 0);
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
