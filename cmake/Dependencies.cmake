# Every dependency comes from Debian packages (scripts/deps.sh lists them).
# Each is found here even where no module uses it yet, so that a missing package
# fails at configure time, not in a later issue.
find_package(PkgConfig REQUIRED)
find_package(OpenMP REQUIRED COMPONENTS CXX)
find_package(Threads REQUIRED)
find_package(OpenSSL REQUIRED)
find_package(MPI REQUIRED COMPONENTS C)
find_package(GDAL CONFIG QUIET)
if(NOT GDAL_FOUND)
  find_package(GDAL REQUIRED)
endif()
find_package(PROJ CONFIG REQUIRED)
find_package(GTest REQUIRED)
find_package(benchmark REQUIRED)
find_package(CLI11 CONFIG REQUIRED)  # the command-line parser of `runout` (header-only)

pkg_check_modules(PETSC REQUIRED IMPORTED_TARGET PETSc)
# Scotch (sequential): the graph partition of a distributed 3D run's mesh.
find_path(SCOTCH_INCLUDE_DIR scotch.h PATH_SUFFIXES scotch REQUIRED)
find_library(SCOTCH_LIBRARY scotch REQUIRED)
find_library(SCOTCHERR_LIBRARY scotcherr REQUIRED)
add_library(runout::scotch INTERFACE IMPORTED)
set_target_properties(runout::scotch PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${SCOTCH_INCLUDE_DIR}"
  INTERFACE_LINK_LIBRARIES "${SCOTCH_LIBRARY};${SCOTCHERR_LIBRARY}")
# HDF5: the MPI build, the same one PETSc links against, so one process never loads two HDF5s.
pkg_check_modules(HDF5 REQUIRED IMPORTED_TARGET hdf5-openmpi)
pkg_check_modules(GRPCPP REQUIRED IMPORTED_TARGET grpc++)
pkg_check_modules(PROTOBUF REQUIRED IMPORTED_TARGET protobuf)
pkg_check_modules(SQLITE3 REQUIRED IMPORTED_TARGET sqlite3)
pkg_check_modules(CAIRO REQUIRED IMPORTED_TARGET cairo)  # maps and figures
pkg_check_modules(PANGOCAIRO REQUIRED IMPORTED_TARGET pangocairo)  # their text (UTF-8, real fonts)

find_program(PROTOC_EXECUTABLE protoc REQUIRED)
find_program(GRPC_CPP_PLUGIN grpc_cpp_plugin REQUIRED)

message(STATUS "runout deps: GDAL ${GDAL_VERSION}, PROJ ${PROJ_VERSION}, PETSc ${PETSC_VERSION}, "
               "HDF5 ${HDF5_VERSION}, gRPC++ ${GRPCPP_VERSION}, protobuf ${PROTOBUF_VERSION}, "
               "SQLite ${SQLITE3_VERSION}")
