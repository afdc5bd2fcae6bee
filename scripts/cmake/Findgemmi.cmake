# Finds gemmi's headers (Debian's gemmi-dev ships no CMake package of its
# own) and the PEGTL its CIF parser needs. Defines gemmi::gemmi, an interface
# target with both include paths.
find_path(gemmi_INCLUDE_DIR gemmi/pdb.hpp)
find_package(pegtl CONFIG QUIET)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(gemmi REQUIRED_VARS gemmi_INCLUDE_DIR)
if(gemmi_FOUND AND NOT TARGET gemmi::gemmi)
  add_library(gemmi::gemmi INTERFACE IMPORTED)
  set_target_properties(gemmi::gemmi PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${gemmi_INCLUDE_DIR}")
  if(TARGET taocpp::pegtl)
    set_property(TARGET gemmi::gemmi APPEND PROPERTY INTERFACE_LINK_LIBRARIES taocpp::pegtl)
  endif()
endif()
mark_as_advanced(gemmi_INCLUDE_DIR)
