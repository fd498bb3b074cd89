#pragma once
// Attributes of HDF5 objects: strings, as the checkpoint files (VOF and depth-averaged) keep their
// format, scenario hash and names; a double, as the frame files (timeseries.h5, fields.h5) keep each
// frame's time.
#include <hdf5.h>

#include <string>

namespace runout::jobs::h5 {

/// Write a string attribute; throws std::runtime_error naming it.
void put_attr_string(hid_t loc, const char* name, const std::string& v);
/// Read a string attribute ("" when it is absent).
std::string get_attr_string(hid_t loc, const char* name);
/// Write a double attribute (IEEE 64-bit little endian); false when that fails.
bool put_attr_double(hid_t loc, const char* name, double v);
/// Read a double attribute (NaN when it is absent or unreadable).
double get_attr_double(hid_t loc, const char* name);

}  // namespace runout::jobs::h5
