__version__ = "0.1"  # the CMake project's VERSION (CMakeLists.txt)
