# SPDX-License-Identifier: MIT
# cmake -DMCS=mcs -DMONO=mono -DSOURCE_DIR=bindings/csharp -DWORK_DIR=<build dir>
#       [-DLIBRARY_DIR=<folder of libsph_mpi.so>] [-DMPIEXEC=mpiexec] -P run_mpi_tests.cmake
#
# Distributed worlds from C# (SphMpi.cs, tests/SphMpiTests.cs): compiles the bindings with
# -define:SPH_MPI, so that every [DllImport] names libsph_mpi, then runs the tests with mono on
# one rank without a launcher (MPI_Init makes a singleton) and, with MPIEXEC, on 2 ranks
# (mpiexec --oversubscribe -n 2 mono ...). libsph_mpi.so and libmpi.so (the tests call MPI_Init)
# must be found: LIBRARY_DIR first on LD_LIBRARY_PATH (run_common.cmake), then the system's.
include("${CMAKE_CURRENT_LIST_DIR}/run_common.cmake")

sph_mcs(-define:SPH_MPI -target:library -doc:Sph.xml -nowarn:1591 -out:Sph.dll "${SOURCE_DIR}/Sph.Generated.cs"
        "${SOURCE_DIR}/Sph.cs" "${SOURCE_DIR}/SphMpi.cs")
sph_mcs(-r:Sph.dll -out:SphMpiTests.exe "${SOURCE_DIR}/tests/SphMpiTests.cs")

# Each run has its own scratch folder: the checkpoint test names its files the same on every rank.
function(sph_run_mpi_tests what scratch)
  file(REMOVE_RECURSE "${WORK_DIR}/${scratch}")
  file(MAKE_DIRECTORY "${WORK_DIR}/${scratch}")
  execute_process(COMMAND ${ARGN} "${MONO}" --debug SphMpiTests.exe "${WORK_DIR}/${scratch}"
                  WORKING_DIRECTORY "${WORK_DIR}" RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the C# distributed-world tests failed on ${what} (exit ${rc})")
  endif()
endfunction()

sph_run_mpi_tests("1 rank, no launcher" scratch_np1)
if(MPIEXEC)
  sph_run_mpi_tests("2 ranks" scratch_np2 "${MPIEXEC}" --oversubscribe -n 2)
endif()
