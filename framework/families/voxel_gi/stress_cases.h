#pragma once
// The voxel_gi family's stress cases (plugin/stress.h), for FamilyInfo::stressCases.

#include "plugin/stress.h"

#include <vector>

namespace rtlab::voxelgi {

std::vector<plugin::StressCase> makeVoxelGiStressCases();

} // namespace rtlab::voxelgi
