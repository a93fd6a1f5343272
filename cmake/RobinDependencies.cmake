# Finds every external dependency from Debian packages (deploy/setup.sh installs them).
# No downloads, no vendored copies.

find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(spdlog REQUIRED)
find_package(tomlplusplus REQUIRED)
find_package(muparser REQUIRED)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json REQUIRED)
find_package(Protobuf REQUIRED)
find_package(cppzmq REQUIRED)
find_package(PkgConfig REQUIRED)
# libdeflate: the zlib streams of the binary .vtu output (vtkZLibDataCompressor layout).
pkg_check_modules(LIBDEFLATE REQUIRED IMPORTED_TARGET libdeflate)
# zlib: only benchmarks/vtu_compression_libraries_benchmark.cpp, which compares the two.
find_package(ZLIB REQUIRED)
# libsodium: SHA-256 of case files in summary.json (libzmq3-dev depends on it already).
pkg_check_modules(SODIUM REQUIRED IMPORTED_TARGET libsodium)

# SuiteSparse 5.12 on Debian 12 ships no CMake configuration for CHOLMOD.
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
add_library(robin_cholmod INTERFACE)
target_include_directories(robin_cholmod SYSTEM INTERFACE ${CHOLMOD_INCLUDE_DIR})
target_link_libraries(robin_cholmod INTERFACE ${CHOLMOD_LIBRARY})
# The BLAS CHOLMOD runs on (libblas.so.3: OpenBLAS through Debian's alternatives once
# libopenblas0 is installed), called directly through its CBLAS interface for the dense
# level-3 products of the trailing block (cholesky.cpp).
find_path(CBLAS_INCLUDE_DIR cblas.h PATH_SUFFIXES x86_64-linux-gnu REQUIRED)
find_library(BLAS_LIBRARY blas REQUIRED)
target_include_directories(robin_cholmod SYSTEM INTERFACE ${CBLAS_INCLUDE_DIR})
target_link_libraries(robin_cholmod INTERFACE ${BLAS_LIBRARY})

# Gmsh's C++ API (libgmsh-dev) has no CMake configuration either.
find_path(GMSH_INCLUDE_DIR gmsh.h REQUIRED)
find_library(GMSH_LIBRARY gmsh REQUIRED)
add_library(robin_gmsh INTERFACE)
target_include_directories(robin_gmsh SYSTEM INTERFACE ${GMSH_INCLUDE_DIR})
target_link_libraries(robin_gmsh INTERFACE ${GMSH_LIBRARY})

if(ROBIN_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(ROBIN_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
