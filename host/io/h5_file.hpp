#pragma once
/// HDF5 files written atomically and read with errors that name the file: the small layer under
/// io_hdf5.cpp (run output) and measured_h5.cpp (measured data). Internal to host/.
#include <fcntl.h>
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace dem::io::h5 {

namespace fs = std::filesystem;

/// Set before any other HDF5 call (C++17 inline variable: once, at the start of the first program file that includes
/// this). HDF5 prints its own error stack for every failed call (some 640 lines for one full disk), where the
/// callers here report each failure once, naming the file; and a file whose close failed (a full disk) stays open
/// inside the library, whose exit handler then flushes it again and crashed (signal 11 in H5F__close_cb): the
/// library's exit handler is not installed, as every file here is closed before its data count.
inline const bool kLibraryQuiet = (H5dont_atexit(), H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr), true);

[[noreturn]] inline void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error("cannot write '" + path + "': " + what);
}

/// A file written under a temporary name of its own (the process and a counter: two writers of one path never
/// share it) and flushed to the disk, waiting to replace `path` by a rename. Until commit() the previous complete
/// version stays in place; a Staged file never committed is removed.
class Staged {
 public:
  template <class Write>
  Staged(std::string path, Write write) : path_(std::move(path)) {
    static std::atomic<unsigned> counter{0};
    tmp_ = path_ + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
    try {
      write(tmp_);
      // Flushed before the rename, so that a crash of the machine cannot leave a renamed file with no data.
      const int fd = ::open(tmp_.c_str(), O_RDONLY);
      if (fd < 0 || ::fsync(fd) != 0) {
        if (fd >= 0) ::close(fd);
        fail(path_, "flush '" + tmp_ + "' to disk");
      }
      ::close(fd);
    } catch (...) {
      std::error_code ec;
      fs::remove(tmp_, ec);
      throw;
    }
  }
  Staged(const Staged&) = delete;
  Staged& operator=(const Staged&) = delete;
  ~Staged() {
    std::error_code ec;
    if (!committed_) fs::remove(tmp_, ec);
  }
  const std::string& tmp() const { return tmp_; }
  void commit() {
    std::error_code ec;
    fs::rename(tmp_, path_, ec);
    if (ec) fail(path_, "rename from '" + tmp_ + "': " + ec.message());
    committed_ = true;
  }

 private:
  std::string path_, tmp_;
  bool committed_ = false;
};

/// Writes through a Staged file, so that a crash or a concurrent reader never sees a half-written file under the
/// final name, and the previous complete version stays in place until the new one is.
template <class Write>
void replace_atomically(const std::string& path, Write write) {
  Staged(path, write).commit();
}

/// Owns one HDF5 identifier, so that every exit path, exceptions included, releases it.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { if (id_ >= 0) closer_(id_); }
  hid_t get() const { return id_; }
  /// For files, closing is the final flush: its failure must be reported, not ignored as in the destructor.
  bool close() { return closer_(std::exchange(id_, H5I_INVALID_HID)) >= 0; }

 private:
  hid_t id_;
  Closer closer_;
};

/// One HDF5 file being written under its temporary name; errors name the final path.
class H5Writer {
 public:
  H5Writer(const std::string& tmp, std::string path)
      : path_(std::move(path)),
        file_(check(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), "create '" + tmp + "'"),
              H5Fclose) {}

  hid_t root() const { return file_.get(); }

  hid_t check(hid_t id, const std::string& what) const {
    if (id < 0) fail(path_, "HDF5 cannot " + what);
    return id;
  }

  void dataset(hid_t loc, const std::string& name, hid_t type, const void* data, const std::vector<hsize_t>& d) {
    Handle space(check(H5Screate_simple(int(d.size()), d.data(), nullptr), "create dataspace for " + name), H5Sclose);
    const hid_t id = H5Dcreate2(loc, name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    Handle set(check(id, "create dataset '" + name + "'"), H5Dclose);
    // HDF5 refuses a null buffer (an empty vector's data()) even when there is nothing to write.
    const bool empty = std::find(d.begin(), d.end(), hsize_t(0)) != d.end();
    if (!empty && H5Dwrite(set.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
      fail(path_, "HDF5 cannot write dataset '" + name + "'");
  }

  /// Scalar attribute on the object at `object` ("." for the root group).
  void attribute(const std::string& object, const std::string& name, hid_t type, const void* value) {
    const std::string what = "attribute '" + name + "' on '" + object + "'";
    Handle space(check(H5Screate(H5S_SCALAR), "create dataspace for " + what), H5Sclose);
    const hid_t id = H5Acreate_by_name(root(), object.c_str(), name.c_str(), type, space.get(), H5P_DEFAULT,
                                       H5P_DEFAULT, H5P_DEFAULT);
    Handle attr(check(id, "create " + what), H5Aclose);
    if (H5Awrite(attr.get(), type, value) < 0) fail(path_, "HDF5 cannot write " + what);
  }

  /// Fixed-length rather than variable-length strings: every reader (h5dump, h5py, ParaView) takes them as is.
  void string_attribute(const std::string& object, const std::string& name, const std::string& value) {
    Handle type(check(H5Tcopy(H5T_C_S1), "copy string type"), H5Tclose);
    if (H5Tset_size(type.get(), value.size() + 1) < 0 || H5Tset_cset(type.get(), H5T_CSET_UTF8) < 0)
      fail(path_, "HDF5 cannot make a string type for attribute '" + name + "'");
    attribute(object, name, type.get(), value.c_str());
  }

  void close() {
    if (!file_.close()) fail(path_, "HDF5 cannot close (flush) the file");
  }

 private:
  std::string path_;
  Handle file_;
};

/// One HDF5 file opened for reading, as untrusted input: every shape, type and size is checked before HDF5
/// writes into a buffer, and every error names the file and the dataset or attribute.
class H5Reader {
 public:
  explicit H5Reader(std::string path)
      : path_(std::move(path)), file_(H5Fopen(path_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose) {
    if (file_.get() < 0) throw std::runtime_error(path_ + ": not a readable HDF5 file");
    hsize_t bytes = 0;
    H5Fget_filesize(file_.get(), &bytes);
    file_bytes_ = static_cast<double>(bytes);
  }
  bool exists(const std::string& name) const { return H5Lexists(file_.get(), name.c_str(), H5P_DEFAULT) > 0; }
  /// A dataset of `columns` values per row (rank 1 when columns is 1, else rank 2 with that many columns), stored
  /// with the type class of `type` (integers may be read as floats, never floats as integers: an index must not be
  /// a rounded number), no larger than the file can hold.
  template <class T>
  std::vector<T> read(const std::string& name, hid_t type, std::size_t columns) const {
    if (!exists(name.substr(0, name.find('/', 1))) || !exists(name))
      throw std::runtime_error(path_ + ": dataset '" + name + "' missing");
    Handle set(H5Dopen2(file_.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
    if (set.get() < 0 || H5Iget_type(set.get()) != H5I_DATASET)
      throw std::runtime_error(path_ + ": '" + name + "' is not a dataset");
    Handle space(H5Dget_space(set.get()), H5Sclose);
    // The rank first: the extents are written one per dimension, and the buffer below holds two.
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 1 || rank > 2)
      throw std::runtime_error(path_ + ": dataset '" + name + "' has rank " + std::to_string(rank) +
                               " (allowed: " + (columns == 1 ? "1" : "2") + ")");
    hsize_t dims[2] = {0, 0};
    H5Sget_simple_extent_dims(space.get(), dims, nullptr);
    if ((rank == 1 && columns != 1) || (rank == 2 && dims[1] != columns))
      throw std::runtime_error(path_ + ": dataset '" + name + "' has " +
                               (rank == 1 ? std::string("one column") : std::to_string(dims[1]) + " columns") +
                               " (allowed: " + std::to_string(columns) + ")");
    Handle stored(H5Dget_type(set.get()), H5Tclose);
    const H5T_class_t have = H5Tget_class(stored.get()), want = H5Tget_class(type);
    if (have != want && !(want == H5T_FLOAT && have == H5T_INTEGER))  // integers convert to floats exactly enough
      throw std::runtime_error(path_ + ": dataset '" + name + "' holds " + class_name(H5Tget_class(stored.get())) +
                               " (allowed: " + class_name(H5Tget_class(type)) + ")");
    // A dataset may declare more rows than it stores (a few bytes on disk for billions of rows): its size in
    // memory is bounded by the file's, with room for compression.
    const double bytes = static_cast<double>(dims[0]) * static_cast<double>(columns) * sizeof(T);
    if (bytes > kCompression * file_bytes_ + kSmallDataset)
      throw std::runtime_error(path_ + ": dataset '" + name + "' declares " + std::to_string(dims[0]) +
                               " rows, more than a file of " + std::to_string(static_cast<long long>(file_bytes_)) +
                               " bytes can hold");
    std::vector<T> out(dims[0] * columns);
    if (!out.empty() && H5Dread(set.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0)
      throw std::runtime_error(path_ + ": cannot read dataset '" + name + "'");
    return out;
  }
  /// A string attribute of the object at `object` ("/" for the root), fixed or variable length (h5py writes a
  /// Python str as the latter); "" when absent. One string (a scalar dataspace), of at most kMaxAttribute bytes:
  /// anything else is refused.
  std::string string_attribute(const std::string& object, const std::string& name) const {
    if (H5Aexists_by_name(file_.get(), object.c_str(), name.c_str(), H5P_DEFAULT) <= 0) return "";
    const std::string what = path_ + ": attribute '" + name + "' of '" + object + "'";
    Handle attr(H5Aopen_by_name(file_.get(), object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    Handle space(H5Aget_space(attr.get()), H5Sclose);
    Handle type(H5Aget_type(attr.get()), H5Tclose);
    if (H5Sget_simple_extent_type(space.get()) != H5S_SCALAR)
      throw std::runtime_error(what + " is not a single value (allowed: one string)");
    if (H5Tget_class(type.get()) != H5T_STRING)
      throw std::runtime_error(what + " is not a string (allowed: one string, fixed or variable length)");
    if (H5Tis_variable_str(type.get()) > 0) {  // h5py's default for a Python str
      Handle mem(H5Tcopy(H5T_C_S1), H5Tclose);
      H5Tset_size(mem.get(), H5T_VARIABLE);
      H5Tset_cset(mem.get(), H5Tget_cset(type.get()));
      char* buf = nullptr;
      if (H5Aread(attr.get(), mem.get(), &buf) < 0 || !buf) throw std::runtime_error(what + " cannot be read");
      std::size_t n = 0;
      while (n <= kMaxAttribute && buf[n]) ++n;
      const std::string text(buf, n);
      H5free_memory(buf);
      if (n > kMaxAttribute)
        throw std::runtime_error(what + " has more than " + std::to_string(kMaxAttribute) + " bytes (allowed: 1 to " +
                                 std::to_string(kMaxAttribute) + ")");
      return text;
    }
    const std::size_t size = H5Tget_size(type.get());
    if (size == 0 || size > kMaxAttribute)
      throw std::runtime_error(what + " has " + std::to_string(size) + " bytes (allowed: 1 to " +
                               std::to_string(kMaxAttribute) + ")");
    std::string text(size, '\0');
    if (H5Aread(attr.get(), type.get(), text.data()) < 0) throw std::runtime_error(what + " cannot be read");
    return text.substr(0, text.find('\0'));
  }
  /// Names of the groups directly under the root, in name order.
  std::vector<std::string> groups() const {
    std::vector<std::string> out;
    H5Literate(file_.get(), H5_INDEX_NAME, H5_ITER_INC, nullptr,
               [](hid_t loc, const char* name, const H5L_info_t*, void* data) -> herr_t {
                 const hid_t obj = H5Oopen(loc, name, H5P_DEFAULT);  // the same call in HDF5 1.10 and 1.12+
                 const bool group = obj >= 0 && H5Iget_type(obj) == H5I_GROUP;
                 if (obj >= 0) H5Oclose(obj);
                 if (group)
                   static_cast<std::vector<std::string>*>(data)->push_back(name);
                 return 0;
               },
               &out);
    return out;
  }
  /// Largest string attribute read, and the room a dataset gets beyond the file's size: compressed data may hold
  /// up to kCompression times its bytes, and a small dataset is never refused.
  static constexpr std::size_t kMaxAttribute = 1 << 20;
  static constexpr double kCompression = 1024, kSmallDataset = 1 << 20;

  /// A 2-D dataset's column count (0 when it is not 2-D).
  std::size_t columns(const std::string& name) const {
    Handle set(H5Dopen2(file_.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
    Handle space(H5Dget_space(set.get()), H5Sclose);
    hsize_t dims[2] = {0, 0};
    return set.get() >= 0 && H5Sget_simple_extent_ndims(space.get()) == 2 &&
                   H5Sget_simple_extent_dims(space.get(), dims, nullptr) == 2
               ? dims[1]
               : 0;
  }

 private:
  static std::string class_name(H5T_class_t c) {
    return c == H5T_INTEGER ? "integers" : c == H5T_FLOAT ? "floating-point numbers" : c == H5T_STRING ? "strings"
                                                                                                      : "other values";
  }
  std::string path_;
  Handle file_;
  double file_bytes_ = 0;
};

}  // namespace dem::io::h5
