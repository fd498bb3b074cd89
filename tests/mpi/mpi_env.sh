# Sourced by the mpi tests' scripts: Open MPI as these tests run it (each rank on one OpenMP thread).
export OMP_NUM_THREADS=1 OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none  # (a container without ptrace refuses cross-memory attach)
export OMPI_MCA_mpi_yield_when_idle=1  # (a waiting rank gives its core to the others: 4 ranks share 2 cores with other tests)
