# The Python client (clients/python, import name runout_client) against a real `runout serve`,
# label service like the C++ service tests. Included from tests/CMakeLists.txt.
#
# It runs with Debian's Python, which has python3-grpcio and python3-protobuf (a python3 of pyenv
# or a venv earlier on PATH may have neither). The test generates the gRPC modules itself, into a
# temporary folder, with protoc (the build's) and grpc_python_plugin (protobuf-compiler-grpc), and
# imports the package from the source tree: no pip install, nothing written to the tree (-B: no
# __pycache__). About 30 s; the timeout leaves room for a loaded machine.
find_program(RUNOUT_SYSTEM_PYTHON python3 PATHS /usr/bin NO_DEFAULT_PATH)
find_program(RUNOUT_GRPC_PYTHON_PLUGIN grpc_python_plugin)
if(NOT RUNOUT_SYSTEM_PYTHON OR NOT RUNOUT_GRPC_PYTHON_PLUGIN)
  # Registered all the same: the test fails and says what is missing, instead of vanishing.
  message(WARNING "service.python_client needs /usr/bin/python3 (python3-grpcio, python3-protobuf) and "
                  "grpc_python_plugin (protobuf-compiler-grpc): python3 = ${RUNOUT_SYSTEM_PYTHON}, "
                  "grpc_python_plugin = ${RUNOUT_GRPC_PYTHON_PLUGIN}")
endif()
add_test(NAME service.python_client
  COMMAND ${RUNOUT_SYSTEM_PYTHON} -B ${PROJECT_SOURCE_DIR}/clients/python/tests/test_client.py
    --runout $<TARGET_FILE:runout> --protoc ${PROTOC_EXECUTABLE} --grpc-python-plugin ${RUNOUT_GRPC_PYTHON_PLUGIN})
set_tests_properties(service.python_client PROPERTIES LABELS service TIMEOUT 180)
