// Precompiled header of every test target (tests/CMakeLists.txt): the heavy,
// stable headers the test files share. Nothing of touchdown's own goes here,
// so editing the library never rebuilds it.
#pragma once
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>
