# Warnings are errors on our own targets only (never on third-party headers, which come in as SYSTEM).
# Not -Wnull-dereference: GCC 12 reports it from Boost.Asio's scheduler after inlining, where system-header
# suppression does not reach, and it cannot be silenced per header.
add_library(fieldguard_warnings INTERFACE)
target_compile_options(fieldguard_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Wnon-virtual-dtor
  -Wold-style-cast -Woverloaded-virtual -Wdouble-promotion -Wformat=2
  -Werror)
