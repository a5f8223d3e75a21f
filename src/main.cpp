#include "fieldguard/app/cli.hpp"

int main(int argc, char** argv) { return fieldguard::app::run_cli(argc, argv); }
