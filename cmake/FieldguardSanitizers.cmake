# FIELDGUARD_SANITIZE=address;undefined or thread. Applied to every target of this project,
# and printed so that a CI log shows it really was applied.
if(FIELDGUARD_SANITIZE)
  string(REPLACE ";" "," _fg_san "${FIELDGUARD_SANITIZE}")
  message(STATUS "fieldguard: building with -fsanitize=${_fg_san}")
  add_compile_options(-fsanitize=${_fg_san} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=${_fg_san})
endif()
