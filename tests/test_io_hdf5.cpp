#include "host/io/io_hdf5.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using dem::io::Output;

namespace {

/// Each test gets its own folder: ctest runs every test twice (1 and 2 OpenMP threads), possibly in parallel.
class IoHdf5 : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = dem::test::scratch_dir(std::string("io/") + info->name());
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Minimal read-back through the HDF5 C API, independent of the writer's helpers.
struct H5Read {
  explicit H5Read(const std::string& path) : file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT)) {}
  ~H5Read() {
    if (file >= 0) H5Fclose(file);
  }
  template <class T>
  std::vector<T> dataset(const std::string& name, hid_t type, std::vector<hsize_t>* dims = nullptr) const {
    const hid_t set = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
    EXPECT_GE(set, 0) << name;
    const hid_t space = H5Dget_space(set);
    std::vector<hsize_t> d(H5Sget_simple_extent_ndims(space));
    H5Sget_simple_extent_dims(space, d.data(), nullptr);
    std::vector<T> out(H5Sget_simple_extent_npoints(space));
    if (!out.empty()) {
      EXPECT_GE(H5Dread(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), 0) << name;
    }
    H5Sclose(space);
    H5Dclose(set);
    if (dims) *dims = d;
    return out;
  }
  std::string string_attribute(const std::string& object, const std::string& name) const {
    const hid_t attr = H5Aopen_by_name(file, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT);
    EXPECT_GE(attr, 0) << object << " " << name;
    const hid_t type = H5Aget_type(attr);
    std::string value(H5Tget_size(type), '\0');
    EXPECT_GE(H5Aread(attr, type, value.data()), 0);
    H5Tclose(type);
    H5Aclose(attr);
    return value.substr(0, value.find('\0'));
  }
  hid_t file;
};

dem::io::Snapshot make_snapshot(long step, int n) {
  dem::io::Snapshot s;
  s.step = step;
  s.time = 1e-6 * double(step);
  s.label = "shear eps_a=5%";
  for (int i = 0; i < n; ++i) {
    s.x.insert(s.x.end(), {0.1 * i, 0.2 * i + 1, -0.5 * i});
    s.v.insert(s.v.end(), {1.0, 2.0, 3.0});
    s.w.insert(s.w.end(), {0.0, 0.0, double(i)});
    s.radius.push_back(1e-3 * (i + 1));
    s.gid.push_back(std::uint32_t(4000000000u + i));
    s.specimen.push_back(i % 2);
  }
  s.scalars.push_back({"coordination", std::vector<double>(n, 4.5)});
  return s;
}

void expect_no_tmp_files(const fs::path& dir) {
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_NE(entry.path().extension(), ".tmp") << entry.path();
}

}  // namespace

TEST_F(IoHdf5, SeriesRoundTripsThroughHdf5AndCsv) {
  Output out(dir_.string());
  const std::vector<std::string> columns{"time[s]", "eps_a[%]", "q/p[-]"};
  out.set_series_columns(columns);
  out.append_series({0.0, 0.0, 0.25});
  out.flush_series();  // a second flush must rewrite the files with all rows
  out.append_series({1.5e-3, 0.125, 1.0 / 3.0});
  out.flush_series();

  H5Read h5(path("series.h5"));
  ASSERT_GE(h5.file, 0);
  std::vector<hsize_t> dims;
  const auto table = h5.dataset<double>("table", H5T_NATIVE_DOUBLE, &dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{2, 3}));
  EXPECT_EQ(table, (std::vector<double>{0.0, 0.0, 0.25, 1.5e-3, 0.125, 1.0 / 3.0}));
  EXPECT_EQ(h5.string_attribute("table", "columns"), "time[s],eps_a[%],q/p[-]");
  EXPECT_EQ(h5.dataset<double>("q_p[-]", H5T_NATIVE_DOUBLE), (std::vector<double>{0.25, 1.0 / 3.0}));
  EXPECT_EQ(h5.string_attribute("q_p[-]", "name"), "q/p[-]");
  EXPECT_EQ(h5.dataset<double>("eps_a[%]", H5T_NATIVE_DOUBLE), (std::vector<double>{0.0, 0.125}));

  const std::string csv = read_text(path("series.csv"));
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "time[s],eps_a[%],q/p[-]");
  EXPECT_NE(csv.find("\n0.0015,0.125,0.3333333333\n"), std::string::npos) << csv;
  expect_no_tmp_files(dir_);
}

TEST_F(IoHdf5, SeriesMisuseThrows) {
  Output out(dir_.string());
  EXPECT_THROW(out.append_series({1.0}), std::invalid_argument);  // no columns yet
  EXPECT_THROW(out.set_series_columns({"a/b", "a_b"}), std::invalid_argument);  // same dataset name
  EXPECT_THROW(out.set_series_columns({"table"}), std::invalid_argument);
  EXPECT_THROW(out.set_series_columns({"x,y"}), std::invalid_argument);
  out.set_series_columns({"a", "b"});
  try {
    out.append_series({1.0, 2.0, 3.0});
    FAIL() << "a row of 3 values for 2 columns was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("3 values"), std::string::npos) << e.what();
  }
  out.append_series({1.0, 2.0});
  EXPECT_THROW(out.set_series_columns({"c"}), std::invalid_argument);
}

TEST_F(IoHdf5, SnapshotRoundTrips) {
  Output out(dir_.string());
  const auto s = make_snapshot(42, 5);
  const dem::io::SurfaceSnapshot surface{{0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2}};
  out.write_snapshot(s, &surface);

  H5Read h5(path("snap_000000042.h5"));
  ASSERT_GE(h5.file, 0);
  std::vector<hsize_t> dims;
  EXPECT_EQ(h5.dataset<double>("x", H5T_NATIVE_DOUBLE, &dims), s.x);
  EXPECT_EQ(dims, (std::vector<hsize_t>{5, 3}));
  EXPECT_EQ(h5.dataset<std::uint32_t>("gid", H5T_NATIVE_UINT32), s.gid);
  EXPECT_EQ(h5.dataset<int>("specimen", H5T_NATIVE_INT), s.specimen);
  EXPECT_EQ(h5.dataset<double>("radius", H5T_NATIVE_DOUBLE), s.radius);
  EXPECT_EQ(h5.dataset<double>("coordination", H5T_NATIVE_DOUBLE), s.scalars[0].second);
  EXPECT_EQ(h5.dataset<int>("surface/triangles", H5T_NATIVE_INT, &dims), surface.triangles);
  EXPECT_EQ(dims, (std::vector<hsize_t>{1, 3}));
  EXPECT_EQ(h5.string_attribute(".", "label"), s.label);
  std::int64_t step = 0;
  const hid_t attr = H5Aopen(h5.file, "step", H5P_DEFAULT);
  EXPECT_GE(H5Aread(attr, H5T_NATIVE_INT64, &step), 0);
  H5Aclose(attr);
  EXPECT_EQ(step, 42);
  expect_no_tmp_files(dir_);
}

TEST_F(IoHdf5, XdmfIndexesEverySnapshot) {
  Output out(dir_.string());
  const dem::io::SurfaceSnapshot surface{{0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2}};
  out.write_snapshot(make_snapshot(0, 3), &surface);
  out.write_snapshot(make_snapshot(1000, 3));
  out.write_snapshot(make_snapshot(1000, 4));  // rewriting a step replaces its entry

  const std::string xdmf = read_text(path("snapshots.xdmf"));
  EXPECT_NE(xdmf.find("CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_NE(xdmf.find("snap_000000000.h5:/x"), std::string::npos);
  EXPECT_NE(xdmf.find("snap_000000000.h5:/surface/triangles"), std::string::npos);
  EXPECT_NE(xdmf.find("snap_000001000.h5:/coordination"), std::string::npos);
  EXPECT_EQ(xdmf.find("snap_000001000.h5:/surface"), std::string::npos);
  EXPECT_NE(xdmf.find("Dimensions=\"4 3\""), std::string::npos);
  const std::string x1000 = "snap_000001000.h5:/x<";
  EXPECT_EQ(xdmf.find(x1000), xdmf.rfind(x1000));
  EXPECT_NE(xdmf.find("</Xdmf>"), std::string::npos);
  expect_no_tmp_files(dir_);
}

TEST_F(IoHdf5, InconsistentSnapshotThrows) {
  Output out(dir_.string());
  auto s = make_snapshot(1, 3);
  s.gid.pop_back();
  EXPECT_THROW(out.write_snapshot(s), std::invalid_argument);
  s = make_snapshot(1, 3);
  s.scalars.push_back({"x", std::vector<double>(3, 0.0)});  // would overwrite the positions
  EXPECT_THROW(out.write_snapshot(s), std::invalid_argument);
  const dem::io::SurfaceSnapshot bad{{0, 0, 0}, {0, 0, 1}};
  EXPECT_THROW(out.write_snapshot(make_snapshot(1, 3), &bad), std::invalid_argument);
}

TEST_F(IoHdf5, UnwritableFolderThrows) {
  fs::create_directories(dir_);
  const std::string file = path("plain_file");
  dem::io::write_text_atomic(file, "x");
  try {
    Output out(file + "/sub");
    FAIL() << "an output folder under a regular file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not writable"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(file + "/sub"), std::string::npos) << e.what();
  }
}

TEST_F(IoHdf5, WriteTextAtomicReplacesAndCleansUpOnFailure) {
  fs::create_directories(dir_);
  dem::io::write_text_atomic(path("a.txt"), "first");
  dem::io::write_text_atomic(path("a.txt"), "second");
  EXPECT_EQ(read_text(path("a.txt")), "second");
  fs::create_directories(dir_ / "occupied" / "child");  // renaming a file over a non-empty folder fails
  EXPECT_THROW(dem::io::write_text_atomic(path("occupied"), "x"), std::runtime_error);
  EXPECT_THROW(dem::io::write_text_atomic(path("missing/a.txt"), "x"), std::runtime_error);
  expect_no_tmp_files(dir_);
}

// A crash between the two renames of a series commit leaves a marker naming the temporaries; the next Output of
// the folder finishes the renames, however the folder is spelled, and never renames anything but the series.
TEST_F(IoHdf5, InterruptedSeriesCommitIsFinishedAndOverwriteClearsWhatARunLeaves) {
  fs::create_directories(dir_);
  auto put = [&](const std::string& name, const std::string& text) { std::ofstream(path(name)) << text; };
  put("series.csv", "old");
  put("series.csv.tmp.1.0", "new");
  put("checkpoint.h5.tmp.1.1", "not a series");
  put(".series_commit", path("series.csv.tmp.1.0") + "\n" + path("checkpoint.h5.tmp.1.1") + "\n");
  Output out(dir_.string() + "/");
  EXPECT_EQ(read_text(path("series.csv")), "new");
  EXPECT_FALSE(fs::exists(path(".series_commit")));
  EXPECT_FALSE(fs::exists(path("checkpoint.h5"))) << "the marker named a file that is not a series";
  // --overwrite: the run's files, its tables and a crashed writer's leftovers go; the user's own stay.
  put(".series_commit", path("series.csv.tmp.2.0") + "\n");
  put("series.csv.tmp.2.0", "a crashed run's");
  for (const char* name : {"summary.csv", "micro_A.csv", "force_chains_A.vtk", "layers.csv", "notes.txt"})
    put(name, "x");
  const dem::io::FolderLock lock = dem::io::claim_output_folder(dir_.string(), false, true);
  for (const char* gone : {"series.csv", "checkpoint.h5.tmp.1.1", ".series_commit", "series.csv.tmp.2.0",
                           "summary.csv", "micro_A.csv", "force_chains_A.vtk", "layers.csv"})
    EXPECT_FALSE(fs::exists(path(gone))) << gone;
  EXPECT_TRUE(fs::exists(path("notes.txt")));
}

// One run per folder: a second lock on a locked folder is refused naming the holder, whether in this process or
// another; the lock goes with its holder, file and all; a lock file left by a killed run (the kernel dropped its
// lock) is taken over, not waited for; a moved lock still releases once.
TEST_F(IoHdf5, FolderLockAdmitsOneRunAtATime) {
  const std::string folder = (dir_ / "locked").string();
  {
    dem::io::FolderLock first(folder);
    EXPECT_TRUE(first.held());
    try {
      dem::io::FolderLock second(folder);
      FAIL() << "a second lock was granted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("is in use by another run (pid " + std::to_string(getpid()) + " on "),
                std::string::npos) << e.what();
    }
    dem::io::FolderLock moved(std::move(first));
    EXPECT_FALSE(first.held());
    EXPECT_TRUE(moved.held());
    EXPECT_THROW(dem::io::FolderLock again(folder), std::runtime_error);
  }
  EXPECT_FALSE(fs::exists(fs::path(folder) / ".triaxdem.lock"));
  std::ofstream(fs::path(folder) / ".triaxdem.lock") << "pid 1 on a machine that crashed\n";
  const dem::io::FolderLock after_crash(folder);
  EXPECT_TRUE(after_crash.held());
}
