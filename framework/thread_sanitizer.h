// Tells ThreadSanitizer what oneTBB's worker threads may see. libtbb is not built with
// ThreadSanitizer, so it cannot see that a flow node's body, run on a worker thread,
// happens after the graph was built on the main thread. The runtime publishes the
// built graph once per run and every body acquires it first. Nothing in other builds.
#pragma once

#if defined(__SANITIZE_THREAD__)
extern "C" void __tsan_acquire(void* address);
extern "C" void __tsan_release(void* address);
#endif

namespace tilth {

#if defined(__SANITIZE_THREAD__)
inline char graph_publication;
inline void publish_graph_to_workers() { __tsan_release(&graph_publication); }
inline void acquire_published_graph() { __tsan_acquire(&graph_publication); }
#else
inline void publish_graph_to_workers() {}
inline void acquire_published_graph() {}
#endif

}  // namespace tilth
