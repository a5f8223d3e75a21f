# Warnings are errors on our own targets only (never on third-party headers, which come in as SYSTEM).
add_library(fieldguard_warnings INTERFACE)
target_compile_options(fieldguard_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Wnon-virtual-dtor
  -Wold-style-cast -Woverloaded-virtual -Wnull-dereference -Wdouble-promotion -Wformat=2
  -Werror)
