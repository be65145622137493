#pragma once
// The occlusion family's stress cases (plugin/stress.h), for FamilyInfo::stressCases.

#include "plugin/stress.h"

#include <vector>

namespace rtlab::occlusion {

std::vector<plugin::StressCase> makeOcclusionStressCases();

} // namespace rtlab::occlusion
