// SPDX-License-Identifier: MIT
// Host allocation failures on demand, for the tests that inject them (tests/reliability/
// test_allocation_failure.cpp, tests/mpi/test_mpi_rank_failure.cpp): allocation_injector.cpp
// replaces the global operator new of the executable that links it (the libraries resolve it
// from the executable, since they export nothing but sph_*). Armed with n, the n-th allocation
// from then on throws std::bad_alloc (or returns null for the nothrow forms), once.
#pragma once

namespace alloc_fault {

void arm(long n);
// Returns whether a failure was injected since arm(), and disarms.
bool disarm();
// Whether the failure injected since the last arm() came on a thread other than arm()'s caller
// (a library thread, or a task system's worker running one of the library's tasks).
bool injected_on_another_thread();

}  // namespace alloc_fault
