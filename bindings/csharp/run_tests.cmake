# SPDX-License-Identifier: MIT
# cmake -DMCS=mcs -DMONO=mono -DSOURCE_DIR=bindings/csharp -DWORK_DIR=<build dir>
#       [-DLIBRARY_DIR=<folder of libsph.so>] -P run_tests.cmake
#
# Compiles the bindings into Sph.dll, the sample, the tests and README.md's two snippets against
# it (mcs, warnings as errors), then runs the snippets and the tests with mono. libsph.so must be
# found by [DllImport("sph")]: LIBRARY_DIR is put first on LD_LIBRARY_PATH, else
# LD_LIBRARY_PATH must name it (run_common.cmake; relative paths are taken from the folder cmake
# was started in). Distributed worlds (SphMpi.cs) are compiled in and refused here: their tests,
# on libsph_mpi, are run_mpi_tests.cmake's.
include("${CMAKE_CURRENT_LIST_DIR}/run_common.cmake")

sph_mcs(-target:library -doc:Sph.xml -nowarn:1591 -out:Sph.dll "${SOURCE_DIR}/Sph.Generated.cs" "${SOURCE_DIR}/Sph.cs"
        "${SOURCE_DIR}/SphMpi.cs")
sph_mcs(-r:Sph.dll -out:Droplets.exe "${SOURCE_DIR}/samples/Droplets.cs")
sph_mcs(-r:Sph.dll -out:SphTests.exe "${SOURCE_DIR}/tests/SphTests.cs")

# README.md's snippets (the block after each "snippet: <name>" marker), as programs: "csharp",
# the two lines at its top, and "csharp-tour", the tour of the API (compiled with `using Sph;`).
file(READ "${SOURCE_DIR}/README.md" readme_text)
function(sph_readme_snippet marker class usings)
  string(FIND "${readme_text}" "<!-- snippet: ${marker} " at)
  if(at EQUAL -1)
    message(FATAL_ERROR "README.md has no '<!-- snippet: ${marker} ' marker")
  endif()
  string(SUBSTRING "${readme_text}" ${at} -1 readme)
  string(FIND "${readme}" "```csharp\n" begin)
  string(SUBSTRING "${readme}" ${begin} -1 readme)
  string(LENGTH "```csharp\n" skip)
  string(SUBSTRING "${readme}" ${skip} -1 readme)
  string(FIND "${readme}" "```" end)
  string(SUBSTRING "${readme}" 0 ${end} snippet)
  file(WRITE "${WORK_DIR}/${class}.cs"
       "${usings}static class ${class}\n{\n    static int Main()\n    {\n${snippet}"
       "        System.Console.WriteLine(\"README snippet ${marker} ran\");\n        return 0;\n    }\n}\n")
  sph_mcs(-r:Sph.dll -out:${class}.exe ${class}.cs)
  execute_process(COMMAND "${MONO}" ${class}.exe WORKING_DIRECTORY "${WORK_DIR}" RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the README snippet ${marker} failed (exit ${rc})")
  endif()
endfunction()
sph_readme_snippet(csharp ReadmeSnippet "")
sph_readme_snippet(csharp-tour ReadmeTour "using Sph;\n")

execute_process(COMMAND "${MONO}" --debug SphTests.exe "${SOURCE_DIR}" WORKING_DIRECTORY "${WORK_DIR}" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the C# binding tests failed (exit ${rc})")
endif()
