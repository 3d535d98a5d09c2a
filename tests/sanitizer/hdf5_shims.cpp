/// Linked into sanitizer builds only (CMakeLists.txt, TRIAXDEM_SANITIZE, with -Wl,--wrap=NAME for each function
/// below). AddressSanitizer sees the writes of instrumented code only, and Debian's libhdf5 is not instrumented:
/// a reader that hands HDF5 a buffer too small for what the file holds (the extents of a dataset of higher rank,
/// an attribute's whole dataspace, a dataset's rows) overflows it unseen. Each wrapper lets HDF5 write into a
/// buffer of the file's size and copies the result out in instrumented code, so that the overflow is reported
/// where the caller's buffer ends.
#include <hdf5.h>

#include <cstring>
#include <vector>

extern "C" {
int __real_H5Sget_simple_extent_dims(hid_t space, hsize_t* dims, hsize_t* maxdims);
herr_t __real_H5Aread(hid_t attr, hid_t type, void* buf);
herr_t __real_H5Dread(hid_t set, hid_t mem_type, hid_t mem_space, hid_t file_space, hid_t xfer, void* buf);

int __wrap_H5Sget_simple_extent_dims(hid_t space, hsize_t* dims, hsize_t* maxdims) {
  hsize_t d[H5S_MAX_RANK], m[H5S_MAX_RANK];
  const int rank = __real_H5Sget_simple_extent_dims(space, d, m);
  for (int k = 0; k < rank; ++k) {
    if (dims) dims[k] = d[k];
    if (maxdims) maxdims[k] = m[k];
  }
  return rank;
}

herr_t __wrap_H5Aread(hid_t attr, hid_t type, void* buf) {
  const hid_t space = H5Aget_space(attr);
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  H5Sclose(space);
  const size_t size = H5Tget_size(type);
  if (n < 0 || size == 0 || H5Tis_variable_str(type) > 0) return __real_H5Aread(attr, type, buf);
  std::vector<unsigned char> all(static_cast<size_t>(n) * size);
  const herr_t r = __real_H5Aread(attr, type, all.data());
  if (r >= 0) std::memcpy(buf, all.data(), all.size());
  return r;
}

herr_t __wrap_H5Dread(hid_t set, hid_t mem_type, hid_t mem_space, hid_t file_space, hid_t xfer, void* buf) {
  if (mem_space != H5S_ALL || file_space != H5S_ALL || H5Tis_variable_str(mem_type) > 0)
    return __real_H5Dread(set, mem_type, mem_space, file_space, xfer, buf);
  const hid_t space = H5Dget_space(set);
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  H5Sclose(space);
  const size_t size = H5Tget_size(mem_type);
  if (n < 0 || size == 0) return __real_H5Dread(set, mem_type, mem_space, file_space, xfer, buf);
  std::vector<unsigned char> all(static_cast<size_t>(n) * size);
  const herr_t r = __real_H5Dread(set, mem_type, mem_space, file_space, xfer, all.data());
  if (r >= 0 && !all.empty()) std::memcpy(buf, all.data(), all.size());
  return r;
}
}
