#pragma once
// The CPUs the launcher gave the ranks on one machine, for the zone rank's conform: mpirun binds
// each rank to a core of its own (OpenMPI does for 2 ranks or fewer), and the ranks sharing the
// zone rank's machine wait for its zone once their own dicing is done. Linux: CPU masks are
// sched_getaffinity's.
#include <sched.h>

#include <functional>

#include <mpi.h>

namespace geode::parallel {

// The CPU masks of the ranks of `comm` on this machine (MPI_COMM_TYPE_SHARED) joined. Collective.
cpu_set_t machine_cpus(MPI_Comm comm);

// Runs `work` in a TBB arena of `threads` threads (0: one per CPU of `cpus`) whose threads,
// the caller's included, may run on any CPU of `cpus` while in it, and have their own masks
// again after it. The process's TBB limit (tbb::global_control) must allow that many.
void run_on_cpus(const cpu_set_t& cpus, int threads, const std::function<void()>& work);

// Waits for `request` without spinning: MPI's blocking calls poll and keep a core busy, which
// the zone rank's conform could use while this rank waits for it.
void wait_quietly(MPI_Request& request);

}  // namespace geode::parallel
