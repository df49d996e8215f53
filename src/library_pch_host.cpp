// Hosts the library's precompiled header (src/library_pch.hpp,
// src/CMakeLists.txt); compiled into no library.
