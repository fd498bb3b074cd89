# The job system's program must not carry the numerics' or the drawing's libraries: its shared
# libraries (ldd) may name neither PETSc, HDF5, MPI nor cairo. Run as: cmake -DBIN=... -P arch_links.cmake
execute_process(COMMAND ldd ${BIN} OUTPUT_VARIABLE libs RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ldd ${BIN} failed")
endif()
foreach(forbidden petsc hdf5 mpi cairo)
  string(REGEX MATCH "lib${forbidden}[^ ]*" hit "${libs}")
  if(hit)
    message(FATAL_ERROR "the job system links ${hit}: it must not need the numerics or the drawing")
  endif()
endforeach()
message(STATUS "job system libraries: none of petsc, hdf5, mpi, cairo")
