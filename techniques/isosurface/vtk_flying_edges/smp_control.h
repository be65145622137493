#pragma once
// vtkSMPTools behind a plain interface. vtkSMPTools.h (VTK 9.1) declares constructors with
// template-ids, which C++20 rejects (GCC 12: "expected unqualified-id"), so only smp_control.cpp,
// compiled as C++17, includes it.

#include <string>

namespace rtlab::isosurface::vtk {

//! vtkSMPTools::GetBackend(): "TBB" in Debian 12's VTK 9.1 (also built: "STDThread", "Sequential").
std::string getSmpBackend();

//! vtkSMPTools::Initialize(threads): with the TBB backend, threads > 0 makes VTK run its parallel
//! loops inside a task arena of that concurrency; 0 drops the arena (all hardware threads, or the
//! limit of the arena the caller runs in). Process-wide state.
void initializeSmp(int threads);

//! vtkSMPTools::GetEstimatedNumberOfThreads(): the concurrency VTK's loops will use.
int getSmpThreadEstimate();

//! Code of a backend name for numeric counters: 0 Sequential, 1 STDThread, 2 TBB, 3 OpenMP,
//! -1 anything else.
double getSmpBackendCode(const std::string& backend);

} // namespace rtlab::isosurface::vtk
