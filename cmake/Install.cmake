# `cmake --install build` (default prefix /usr/local) and `cpack -G DEB` (a Debian package): the
# program, the bundled scenarios and their data, the docs, the QGIS provider and the Python client.
#
#   bin/runout                                   the program (RPATH to Debian's MPI, HDF5 and PETSc
#                                                folders, which are outside the linker's default path)
#   share/runout/scenarios/                      the bundled scenarios with their data
#   share/runout/qgis/runout_provider/           the QGIS Processing provider (a plugin folder)
#   share/doc/runout/                            README and docs/
#   lib/python3/dist-packages/runout_client/     the Python client with its generated gRPC modules
#                                                (on Debian's python3 path under /usr and /usr/local)
#
# Components: program (the program, scenarios, docs, QGIS provider) and python_client, so that
# `cmake --install build --component python_client` installs the client alone.
include(GNUInstallDirs)
set(CMAKE_INSTALL_RPATH_USE_LINK_PATH ON)
set_target_properties(runout PROPERTIES INSTALL_RPATH_USE_LINK_PATH ON)

install(TARGETS runout RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT program)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/scenarios/ DESTINATION ${CMAKE_INSTALL_DATADIR}/runout/scenarios COMPONENT program
        PATTERN "*.aux.xml" EXCLUDE)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT program)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT program)
if(EXISTS ${PROJECT_SOURCE_DIR}/clients/qgis/runout_provider)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/clients/qgis/runout_provider DESTINATION ${CMAKE_INSTALL_DATADIR}/runout/qgis
          COMPONENT program PATTERN "__pycache__" EXCLUDE)
endif()

# The Python client: its gRPC modules generated from service/proto into the build folder (never into
# the source tree) by the client's own generator, with Debian's protoc and grpc_python_plugin.
find_program(RUNOUT_PYTHON3 python3 PATHS /usr/bin NO_DEFAULT_PATH)
find_program(RUNOUT_GRPC_PYTHON_PLUGIN_FOR_INSTALL grpc_python_plugin)
set(RUNOUT_PY_STUBS ${CMAKE_BINARY_DIR}/python-client)
file(GLOB RUNOUT_PROTOS ${PROJECT_SOURCE_DIR}/service/proto/runout/v1/*.proto)
if(RUNOUT_PYTHON3 AND RUNOUT_GRPC_PYTHON_PLUGIN_FOR_INSTALL)
  add_custom_command(OUTPUT ${RUNOUT_PY_STUBS}/runout_client/_proto/__init__.py
    COMMAND ${RUNOUT_PYTHON3} -B ${PROJECT_SOURCE_DIR}/clients/python/generate_stubs.py --out ${RUNOUT_PY_STUBS}
            --protoc ${PROTOC_EXECUTABLE} --grpc-python-plugin ${RUNOUT_GRPC_PYTHON_PLUGIN_FOR_INSTALL}
    DEPENDS ${RUNOUT_PROTOS} ${PROJECT_SOURCE_DIR}/clients/python/generate_stubs.py
    COMMENT "Generating the Python client's gRPC modules")
  add_custom_target(python_client_stubs ALL DEPENDS ${RUNOUT_PY_STUBS}/runout_client/_proto/__init__.py)
  set(RUNOUT_PY_DEST lib/python3/dist-packages)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/clients/python/runout_client DESTINATION ${RUNOUT_PY_DEST} COMPONENT python_client
          PATTERN "__pycache__" EXCLUDE)
  install(DIRECTORY ${RUNOUT_PY_STUBS}/runout_client/_proto DESTINATION ${RUNOUT_PY_DEST}/runout_client COMPONENT python_client
          PATTERN "__pycache__" EXCLUDE)
else()
  message(WARNING "the Python client is not installed: it needs /usr/bin/python3 and grpc_python_plugin (protobuf-compiler-grpc)")
endif()

# The Debian package (cpack -G DEB in the build folder): its library dependencies from
# dpkg-shlibdeps, plus what the program and the client use at run time without linking it.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME runout)
set(CPACK_PACKAGE_VENDOR "runout")
set(CPACK_PACKAGE_CONTACT "runout maintainers <runout@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Hazard mapping for rapid granular flows (avalanches, debris and rock avalanches)")
set(CPACK_PACKAGE_INSTALL_DIRECTORY runout)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "fonts-dejavu-core, gdal-data, proj-data, python3-grpcio, python3-protobuf")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "qgis, python3-qgis, slurm-client")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
include(CPack)
