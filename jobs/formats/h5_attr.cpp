#include "jobs/formats/h5_attr.hpp"

#include <cmath>
#include <stdexcept>

namespace runout::jobs::h5 {

void put_attr_string(hid_t loc, const char* name, const std::string& v) {
  hid_t t = H5Tcopy(H5T_C_S1);
  H5Tset_size(t, v.size() + 1);
  hid_t sp = H5Screate(H5S_SCALAR);
  hid_t a = H5Acreate2(loc, name, t, sp, H5P_DEFAULT, H5P_DEFAULT);
  const herr_t st = a < 0 ? -1 : H5Awrite(a, t, v.c_str());
  if (a >= 0) H5Aclose(a);
  H5Sclose(sp);
  H5Tclose(t);
  if (st < 0) throw std::runtime_error(std::string("checkpoint: cannot write attribute ") + name);
}

std::string get_attr_string(hid_t loc, const char* name) {
  if (H5Aexists(loc, name) <= 0) return {};
  hid_t a = H5Aopen(loc, name, H5P_DEFAULT);
  hid_t t = H5Aget_type(a);
  const std::size_t n = H5Tget_size(t);
  std::string v(n, '\0');
  hid_t mt = H5Tcopy(H5T_C_S1);
  H5Tset_size(mt, n);
  H5Aread(a, mt, v.data());
  H5Tclose(mt);
  H5Tclose(t);
  H5Aclose(a);
  v.resize(v.find('\0') == std::string::npos ? v.size() : v.find('\0'));
  return v;
}

bool put_attr_double(hid_t loc, const char* name, double v) {
  hid_t sp = H5Screate(H5S_SCALAR);
  hid_t a = H5Acreate2(loc, name, H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT);
  const herr_t st = a < 0 ? -1 : H5Awrite(a, H5T_NATIVE_DOUBLE, &v);
  if (a >= 0) H5Aclose(a);
  H5Sclose(sp);
  return st >= 0;
}

double get_attr_double(hid_t loc, const char* name) {
  double v = NAN;
  if (H5Aexists(loc, name) <= 0) return v;
  hid_t a = H5Aopen(loc, name, H5P_DEFAULT);
  if (a < 0) return v;
  if (H5Aread(a, H5T_NATIVE_DOUBLE, &v) < 0) v = NAN;
  H5Aclose(a);
  return v;
}

}  // namespace runout::jobs::h5
