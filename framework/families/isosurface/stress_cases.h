#pragma once
// The isosurface family's stress cases (plugin/stress.h), for FamilyInfo::stressCases.

#include "plugin/stress.h"

#include <vector>

namespace rtlab::isosurface {

std::vector<plugin::StressCase> makeIsosurfaceStressCases();

} // namespace rtlab::isosurface
