#include "smp_control.h"

#include <vtkSMPTools.h>

namespace rtlab::isosurface::vtk {

std::string getSmpBackend()
{
    const char* name = vtkSMPTools::GetBackend();
    return name != nullptr ? std::string(name) : std::string();
}

void initializeSmp(int threads)
{
    vtkSMPTools::Initialize(threads);
}

int getSmpThreadEstimate()
{
    return vtkSMPTools::GetEstimatedNumberOfThreads();
}

double getSmpBackendCode(const std::string& backend)
{
    if (backend == "Sequential")
        return 0.0;
    if (backend == "STDThread")
        return 1.0;
    if (backend == "TBB")
        return 2.0;
    if (backend == "OpenMP")
        return 3.0;
    return -1.0;
}

} // namespace rtlab::isosurface::vtk
