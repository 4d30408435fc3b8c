# Finds Debian's LCM (no CMake config there; its pkg-config file wants glib's -dev package).
# Defines the imported target lcm::lcm and LCM_GEN_EXECUTABLE, LCM_JAR.
find_path(LCM_INCLUDE_DIR lcm/lcm-cpp.hpp)
find_library(LCM_LIBRARY lcm)
find_program(LCM_GEN_EXECUTABLE lcm-gen)
find_file(LCM_JAR lcm.jar PATHS /usr/share/java /usr/local/share/java)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(LCM REQUIRED_VARS LCM_LIBRARY LCM_INCLUDE_DIR LCM_GEN_EXECUTABLE)
if(LCM_FOUND AND NOT TARGET lcm::lcm)
  add_library(lcm::lcm UNKNOWN IMPORTED)
  set_target_properties(lcm::lcm PROPERTIES
    IMPORTED_LOCATION "${LCM_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${LCM_INCLUDE_DIR}")
endif()
