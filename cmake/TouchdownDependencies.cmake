# Third-party dependencies, all from Debian's archive (scripts/setup-deps.sh).
# Only Eigen is part of the public interface; the rest stays behind .cpp files.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(assimp REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(Threads REQUIRED)
# nlohmann-json: the apps' --json output and the violation search's results
# directory (header-only, used in a few translation units).
find_package(nlohmann_json 3 REQUIRED)
if(TOUCHDOWN_BUILD_APPS OR TOUCHDOWN_BUILD_BENCHMARKS OR (TOUCHDOWN_BUILD_TESTS AND NOT TOUCHDOWN_ONBOARD_ONLY))
  find_package(CLI11 REQUIRED)
endif()
if(TOUCHDOWN_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(TOUCHDOWN_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
# Landing twin: ODE (double precision) for dynamics, libccd for convex
# contact generation. oneTBB only because pagmo2's exported target names
# TBB::tbb; touchdown's own parallel runs use core/batch.hpp's threads.
find_package(PkgConfig REQUIRED)
pkg_check_modules(ODE REQUIRED IMPORTED_TARGET ode)
pkg_check_modules(CCD REQUIRED IMPORTED_TARGET ccd)
if(NOT TOUCHDOWN_ONBOARD_ONLY)
  find_package(TBB REQUIRED)
endif()
# LED pose: OpenCV for image I/O, rendering and the ArUco baseline; Ceres
# for the constellation bundle adjustment.
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs calib3d aruco videoio dnn)
if(NOT TOUCHDOWN_ONBOARD_ONLY)
  find_package(Ceres 2 REQUIRED)
endif()
# Landing trajectory: NLopt for the time allocation (and SLSQP as the QP
# solver's reference in tests and benchmarks).
find_package(NLopt REQUIRED)
if(TOUCHDOWN_ONBOARD_ONLY)
  # pose_calib, scenario, search and search_mpi are not onboard: src/CMakeLists.txt
  # still declares them, but they are left out of the build (CMakeLists.txt);
  # these empty stand-ins for their dependencies let CMake generate.
  foreach(left_out Ceres::ceres Pagmo::pagmo MPI::MPI_CXX)
    add_library(${left_out} INTERFACE IMPORTED)
  endforeach()
  return()
endif()
# Landing test world: FCL for the drone's collisions with scene objects.
find_package(fcl 0.7 REQUIRED)
# Violation search: pagmo2 for NSGA-II's non-dominated sorting and crowding
# distance (privately, in one translation unit); Open MPI for campaigns
# across processes and machines (only the campaign runner, touchdown::search_mpi).
find_package(pagmo REQUIRED)
find_package(MPI REQUIRED COMPONENTS CXX)
