/// Measured data in HDF5 (host/data/measured.hpp): one group per material, a `table` of numbers in it, its columns
/// named in an attribute. Read into the same text table as a CSV, so that one parser validates both.
#include <cstdio>

#include "host/io/h5_file.hpp"
#include "host/data/measured.hpp"
#include "host/util/text_format.hpp"

namespace dem {

MeasuredTextTable read_measured_h5(const std::string& path) {
  try {
    const io::h5::H5Reader f(path);
    MeasuredTextTable t;
    for (const std::string& material : f.groups()) {
      const std::string table = "/" + material + "/table";
      const std::string names = f.string_attribute(table, "columns");
      if (!f.exists(table) || names.empty())
        throw DataError(path + ":/" + material + ": no dataset 'table' with a string attribute 'columns'");
      std::vector<std::string> header{"material"};
      for (const std::string& c : split_fields(names)) header.push_back(c);
      if (t.header_at.empty()) {
        t.header = header;
        t.header_at = path + ":" + table + " columns";
      } else if (header != t.header) {
        throw DataError(path + ":" + table + " columns: '" + names + "' differ from the first group's");
      }
      const std::size_t ncol = f.columns(table);
      if (ncol + 1 != header.size())
        throw DataError(path + ":" + table + ": " + std::to_string(ncol) + " columns of numbers, 'columns' names " +
                        std::to_string(header.size() - 1));
      const std::vector<double> v = f.read<double>(table, H5T_NATIVE_DOUBLE, ncol);
      char cell[32];
      for (std::size_t r = 0; r * ncol < v.size(); ++r) {
        MeasuredTextTable::Row row{path + ":" + table + " row " + std::to_string(r + 1), {material}};
        for (std::size_t c = 0; c < ncol; ++c) {
          std::snprintf(cell, sizeof cell, "%.17g", v[r * ncol + c]);  // reads back to the same double
          row.cells.push_back(cell);
        }
        t.rows.push_back(row);
      }
    }
    if (t.header_at.empty()) throw DataError(path + ": no material groups");
    // A text value has no place in the table of numbers: the file says it once, and every row carries it.
    const std::string measure = f.string_attribute("/", "q_measure");
    if (!measure.empty()) {
      t.header.push_back("q_measure");
      for (MeasuredTextTable::Row& r : t.rows) r.cells.push_back(measure);
    }
    return t;
  } catch (const DataError&) {
    throw;
  } catch (const std::exception& e) {
    throw DataError(e.what());
  }
}

void write_measured_h5(const std::string& path, const std::vector<std::string>& columns,
                       const std::map<std::string, std::vector<std::vector<double>>>& rows,
                       const std::string& comment, const std::string& q_measure) {
  std::string names;
  for (const std::string& c : columns) names += (names.empty() ? "" : ",") + c;
  try {
    io::h5::replace_atomically(path, [&](const std::string& tmp) {
      io::h5::H5Writer f(tmp, path);
      f.string_attribute("/", "comment", comment);
      if (!q_measure.empty()) f.string_attribute("/", "q_measure", q_measure);
      for (const auto& [material, table] : rows) {
        if (material.empty() || material.find('/') != std::string::npos || material == ".")
          throw DataError(path + ": material '" + material + "' cannot name an HDF5 group");
        io::h5::Handle group(f.check(H5Gcreate2(f.root(), material.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                                     "create group '" + material + "'"),
                             H5Gclose);
        std::vector<double> flat;
        for (const std::vector<double>& r : table) flat.insert(flat.end(), r.begin(), r.end());
        f.dataset(group.get(), "table", H5T_NATIVE_DOUBLE, flat.data(), {table.size(), columns.size()});
        f.string_attribute("/" + material + "/table", "columns", names);
      }
      f.close();
    });
  } catch (const DataError&) {
    throw;
  } catch (const std::exception& e) {
    throw DataError(e.what());
  }
}

}  // namespace dem
