/// The small text tables triaxdem reads back (seeds: files of each kind), chosen by the first byte: a study case's
/// summary.csv, a calibration reference-values CSV and the specimen cache. (Measured data in HDF5 form: the raw
/// HDF5 harness.)
#include "fuzz_file.hpp"
#include "host/data/measured.hpp"
#include "host/triax/specimen.hpp"
#include "host/study/study.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  switch (data[0] % 3) {
    case 0:
      return dem::fuzz::read_bytes(data + 1, size - 1, ".summary.csv", [](const std::string& p) { dem::read_summary(p); });
    case 1:
      return dem::fuzz::read_bytes(data + 1, size - 1, ".reference.csv", [](const std::string& p) {
        dem::load_reference(p, [](const std::string&) {});
      });
    default:
      return dem::fuzz::read_bytes(data + 1, size - 1, ".specimen.csv", [](const std::string& p) {
        dem::Specimen sp;
        dem::load_specimen(p, "fuzz", sp);
      });
  }
}
