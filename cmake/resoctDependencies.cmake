# Finds every dependency from the system (Debian packages); nothing is downloaded or vendored.
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(glm REQUIRED)
find_package(zstd REQUIRED)
pkg_check_modules(LZ4 REQUIRED IMPORTED_TARGET liblz4)
find_package(ZLIB REQUIRED)
find_package(OpenMP REQUIRED COMPONENTS CXX)
find_package(nlohmann_json REQUIRED)
find_package(PNG REQUIRED)
# Volume file formats: blosc for OME-Zarr chunks, libtiff for TIFF stacks.
pkg_check_modules(BLOSC REQUIRED IMPORTED_TARGET blosc)
find_package(TIFF REQUIRED)

find_package(Vulkan QUIET)
find_program(RESOCT_GLSLANG_VALIDATOR NAMES glslangValidator)

if(TARGET zstd::libzstd_shared)
  set(RESOCT_ZSTD_TARGET zstd::libzstd_shared)
else()
  set(RESOCT_ZSTD_TARGET zstd::libzstd_static)
endif()

if(RESOCT_BUILD_EXAMPLES OR RESOCT_BUILD_TESTS OR RESOCT_BUILD_BENCH)
  find_package(CLI11 REQUIRED)
endif()
# The interactive viewer resoct-view (examples/tools/viewer/) is built only where GLFW 3 is found.
if(RESOCT_BUILD_EXAMPLES)
  find_package(glfw3 3.3 QUIET)
endif()
if(RESOCT_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(RESOCT_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()

# Python bindings (pybind11-dev, python3-dev, python3-numpy): Debian's interpreter, for which those
# packages are built, unless -DPython_EXECUTABLE= names another. A python3 earlier on PATH (pyenv,
# a virtualenv) usually lacks numpy and Debian's pybind11.
if(NOT DEFINED Python_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python_EXECUTABLE /usr/bin/python3)
endif()
find_package(Python 3.8 QUIET COMPONENTS Interpreter Development.Module)
set(RESOCT_PYTHON_FOUND OFF)
if(Python_FOUND)
  set(PYBIND11_FINDPYTHON ON)
  find_package(pybind11 CONFIG QUIET)
  execute_process(COMMAND ${Python_EXECUTABLE} -c "import numpy" RESULT_VARIABLE _resoct_numpy_rc
                  OUTPUT_QUIET ERROR_QUIET)
  if(pybind11_FOUND AND _resoct_numpy_rc EQUAL 0)
    set(RESOCT_PYTHON_FOUND ON)
  endif()
endif()
