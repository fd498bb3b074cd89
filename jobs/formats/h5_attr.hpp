#pragma once
// String attributes of HDF5 objects, as the checkpoint files (VOF and depth-averaged) keep their
// format, scenario hash and names.
#include <hdf5.h>

#include <string>

namespace runout::jobs::h5 {

/// Write a string attribute; throws std::runtime_error naming it.
void put_attr_string(hid_t loc, const char* name, const std::string& v);
/// Read a string attribute ("" when it is absent).
std::string get_attr_string(hid_t loc, const char* name);

}  // namespace runout::jobs::h5
