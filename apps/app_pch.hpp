// Precompiled header of the apps (apps/CMakeLists.txt): CLI11 and
// nlohmann-json take about 12 s to parse per app; they are compiled once.
#pragma once
#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>
