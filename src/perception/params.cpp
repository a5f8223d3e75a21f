// perception arrives with the obstacle-detection issue; its parameter structs live in the header.
#include "fieldguard/perception/params.hpp"
