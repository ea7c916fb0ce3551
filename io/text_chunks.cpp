#include <geode/io/text_chunks.hpp>

#include <fmt/compile.h>
#include <fmt/format.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <mutex>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::io {

using primal::index_cast;

char* put_number(char* at, std::int64_t x) { return fmt::format_to(at, FMT_COMPILE("{}"), x); }
char* put_number(char* at, double x) { return fmt::format_to(at, FMT_COMPILE("{}"), x); }

void write_in_chunks(
    std::size_t n, std::size_t chunk,
    const std::function<void(std::size_t begin, std::size_t end, std::string& out)>& make,
    const std::function<void(std::string_view bytes)>& write) {
  const std::size_t chunks = (n + chunk - 1) / chunk;
  std::size_t next = 0;
  // The chunks' strings, reused once written: a fresh one's pages were faulted in and cleared
  // by the kernel for every chunk (a tenth of a 150 MB ASCII .msh's writing).
  std::mutex pool_mutex;
  std::vector<std::string> pool;
  // TBB's pipeline: chunk numbers in order, made in parallel, written in their order. Two chunks
  // in flight per thread keep every thread busy while one is written, and few are held.
  tbb::parallel_pipeline(2 * index_cast<std::size_t>(tbb::this_task_arena::max_concurrency()),
                         tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order,
                                                             [&](tbb::flow_control& control) {
                                                               if (next == chunks) control.stop();
                                                               return next++;
                                                             }) &
                             tbb::make_filter<std::size_t, std::string>(
                                 tbb::filter_mode::parallel,
                                 [&](std::size_t c) {
                                   std::string out;
                                   {
                                     const std::lock_guard lock(pool_mutex);
                                     if (!pool.empty()) {
                                       out = std::move(pool.back());
                                       pool.pop_back();
                                     }
                                   }
                                   out.clear();  // its capacity kept
                                   make(c * chunk, std::min(n, (c + 1) * chunk), out);
                                   return out;
                                 }) &
                             tbb::make_filter<std::string, void>(
                                 tbb::filter_mode::serial_in_order, [&](std::string out) {
                                   write(out);
                                   const std::lock_guard lock(pool_mutex);
                                   pool.push_back(std::move(out));
                                 }));
}

}  // namespace geode::io
