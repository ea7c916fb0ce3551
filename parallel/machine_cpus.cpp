#include <geode/parallel/machine_cpus.hpp>

#include <tbb/task_arena.h>
#include <tbb/task_scheduler_observer.h>

#include <chrono>
#include <thread>
#include <vector>

namespace geode::parallel {

namespace {

// Gives every thread entering the arena the wider mask, and gives it back its own on leaving.
class WidenedCpus : public tbb::task_scheduler_observer {
 public:
  WidenedCpus(tbb::task_arena& arena, const cpu_set_t& cpus)
      : tbb::task_scheduler_observer(arena), cpus_(cpus) {
    observe(true);
  }
  ~WidenedCpus() override { observe(false); }
  void on_scheduler_entry(bool) override {
    cpu_set_t own;
    if (sched_getaffinity(0, sizeof own, &own) == 0) own_ = own, saved_ = true;
    sched_setaffinity(0, sizeof cpus_, &cpus_);
  }
  void on_scheduler_exit(bool) override {
    if (saved_) sched_setaffinity(0, sizeof own_, &own_);
  }

 private:
  cpu_set_t cpus_;
  // Per thread: a worker leaves the arena on the thread it entered on.
  static thread_local cpu_set_t own_;
  static thread_local bool saved_;
};
thread_local cpu_set_t WidenedCpus::own_;
thread_local bool WidenedCpus::saved_ = false;

}  // namespace

cpu_set_t machine_cpus(MPI_Comm comm) {
  cpu_set_t mine;
  CPU_ZERO(&mine);
  if (sched_getaffinity(0, sizeof mine, &mine) != 0) CPU_ZERO(&mine);
  MPI_Comm local;
  MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &local);
  int n = 1;
  MPI_Comm_size(local, &n);
  std::vector<cpu_set_t> all(static_cast<std::size_t>(n));
  MPI_Allgather(&mine, sizeof mine, MPI_BYTE, all.data(), sizeof mine, MPI_BYTE, local);
  MPI_Comm_free(&local);
  cpu_set_t joined;
  CPU_ZERO(&joined);
  for (cpu_set_t& s : all) CPU_OR(&joined, &joined, &s);
  return joined;
}

void run_on_cpus(const cpu_set_t& cpus, int threads, const std::function<void()>& work) {
  const int count = CPU_COUNT(&cpus);
  tbb::task_arena arena(threads > 0 ? threads : std::max(count, 1));
  WidenedCpus widened(arena, cpus);
  arena.execute(work);
}

void wait_quietly(MPI_Request& request) {
  for (int done = 0;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

}  // namespace geode::parallel
