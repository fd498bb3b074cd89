// Versions of the program and of every library it links (also a link check of the dependencies).
#include <CLI/CLI.hpp>
#include <H5public.h>
#include <gdal.h>
#include <google/protobuf/stubs/common.h>
#include <grpcpp/grpcpp.h>
#include <petscsys.h>
#include <proj.h>
#include <sqlite3.h>

#include <iostream>
#include <sstream>

#include "service/cli/commands.hpp"

namespace runout::cli {

std::string version_report() {
  std::ostringstream o;
  o << "runout " << RUNOUT_VERSION << "\n";
  o << "  GDAL     " << GDALVersionInfo("RELEASE_NAME") << "\n";
  o << "  PROJ     " << proj_info().release << "\n";
  int major = 0, minor = 0, sub = 0;
  PetscGetVersionNumber(&major, &minor, &sub, nullptr);
  o << "  PETSc    " << major << "." << minor << "." << sub << "\n";
  unsigned hmaj = 0, hmin = 0, hrel = 0;
  H5get_libversion(&hmaj, &hmin, &hrel);
  o << "  HDF5     " << hmaj << "." << hmin << "." << hrel << "\n";
  o << "  gRPC     " << grpc::Version() << "\n";
  o << "  protobuf " << google::protobuf::internal::VersionString(GOOGLE_PROTOBUF_VERSION) << "\n";
  o << "  SQLite   " << sqlite3_libversion() << "\n";
  return o.str();
}

int version(const std::vector<std::string>& args) {
  CLI::App app{"Print the program version and the versions of the libraries it links.", "runout version"};
  prepare(app);
  if (const int rc = parse_args(app, args); rc >= 0) return rc;
  std::cout << version_report();
  return kOk;
}

}  // namespace runout::cli
