//! Data parallelism where the platform has threads: natively on rayon's pool; in wasm built with
//! the `threads` feature on rayon's pool of Web Workers (started from JavaScript by
//! `initThreadPool`); in the plain wasm build (one thread, no shared memory) as the same loops
//! run in order.
//!
//! Every parallel section hands out pieces of work (slabs of a grid, chunks of a list) whose
//! results are put together in the pieces' order, and either the cut never depends on the number
//! of threads, or (see [`piece_len`]) the joined pieces are by construction what one piece gives:
//! the output is the same bit for bit with one thread or many.
//!
//! Progress checkpoints ([`crate::progress`]) are thread-local: the callers keep them outside the
//! closures given here, between parallel sections, on the job's own thread.

#[cfg(any(not(target_arch = "wasm32"), feature = "threads"))]
use rayon::prelude::*;

/// Whether the parallel sections go to rayon: always natively; in the threaded wasm build once
/// [`pool_started`] (rayon's global pool would otherwise try to spawn its own threads there, which
/// wasm cannot); the plain wasm build has no rayon.
#[cfg(any(not(target_arch = "wasm32"), feature = "threads"))]
fn pooled() -> bool {
    #[cfg(not(target_arch = "wasm32"))]
    {
        true
    }
    #[cfg(all(target_arch = "wasm32", feature = "threads"))]
    {
        POOL_STARTED.load(std::sync::atomic::Ordering::Acquire)
    }
}

#[cfg(all(target_arch = "wasm32", feature = "threads"))]
static POOL_STARTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Records that rayon's global pool runs on Web Workers (`startThreads` in [`crate::wasm`]).
#[cfg(all(target_arch = "wasm32", feature = "threads"))]
pub fn pool_started() {
    POOL_STARTED.store(true, std::sync::atomic::Ordering::Release);
}

/// `f(0), f(1), …, f(n - 1)`, in that order, computed in parallel where there are threads.
pub fn map<R: Send>(n: usize, f: impl Fn(usize) -> R + Sync + Send) -> Vec<R> {
    #[cfg(any(not(target_arch = "wasm32"), feature = "threads"))]
    if pooled() {
        return (0..n).into_par_iter().map(f).collect();
    }
    (0..n).map(f).collect()
}

/// [`map`] for work that needs buffers: `f(&mut s, i)` with an `s` from `init` per run of
/// indices one thread takes (one in all without threads), so the buffers are made a few times,
/// not once per index.
pub fn map_with<S, R: Send>(
    n: usize,
    init: impl Fn() -> S + Sync + Send,
    f: impl Fn(&mut S, usize) -> R + Sync + Send,
) -> Vec<R> {
    #[cfg(any(not(target_arch = "wasm32"), feature = "threads"))]
    if pooled() {
        return (0..n).into_par_iter().map_init(&init, |s, i| f(s, i)).collect();
    }
    let mut s = init();
    (0..n).map(|i| f(&mut s, i)).collect()
}

/// Calls `f(chunk_index, chunk)` for each `chunk_len`-long piece of `data` (the last may be
/// shorter), in parallel where there are threads, and returns the results in chunk order.
pub fn map_chunks_mut<T: Send, R: Send>(
    data: &mut [T],
    chunk_len: usize,
    f: impl Fn(usize, &mut [T]) -> R + Sync + Send,
) -> Vec<R> {
    #[cfg(any(not(target_arch = "wasm32"), feature = "threads"))]
    if pooled() {
        return data.par_chunks_mut(chunk_len).enumerate().map(|(i, c)| f(i, c)).collect();
    }
    data.chunks_mut(chunk_len).enumerate().map(|(i, c)| f(i, c)).collect()
}

/// `(a(), b())`, the two on different threads where there are threads to spare.
pub fn join<A: Send, B: Send>(a: impl FnOnce() -> A + Send, b: impl FnOnce() -> B + Send) -> (A, B) {
    #[cfg(any(not(target_arch = "wasm32"), feature = "threads"))]
    if pooled() {
        return rayon::join(a, b);
    }
    (a(), b())
}

/// How long the pieces of `total` items are to be cut: one piece where there is one thread (no
/// joining to pay for), else about four per thread for balance, at least `min` long. Only for
/// sections whose joined output is, by construction, that of one piece (Marching Cubes' and
/// EMC's slabs).
pub fn piece_len(total: usize, min: usize) -> usize {
    match threads() {
        0 | 1 => total.max(1),
        n => total.div_ceil(4 * n).max(min).max(1),
    }
}

/// Threads the parallel sections can use (1 in the plain wasm build, and in the threaded one
/// before its pool is started).
pub fn threads() -> usize {
    #[cfg(any(not(target_arch = "wasm32"), feature = "threads"))]
    if pooled() {
        return rayon::current_num_threads();
    }
    1
}

/// Sets how many threads the parallel sections use from now on, for the whole process (the
/// CLI's `--threads`); rayon's default is one per core. Only the first call can take effect.
#[cfg(not(target_arch = "wasm32"))]
pub fn set_threads(n: usize) -> Result<(), crate::Error> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(n.max(1))
        .build_global()
        .map_err(|e| crate::Error::InvalidOption(format!("cannot set the thread count: {e}")))
}

/// Runs `job` with the parallel sections on a pool of `n` threads of its own (`job` itself runs on
/// one of them, so a progress hook of the calling thread does not see its checkpoints): for
/// comparing thread counts, and for the CLI's `--threads`. In wasm, runs `job` as it is.
pub fn with_threads<R: Send>(n: usize, job: impl FnOnce() -> R + Send) -> R {
    #[cfg(not(target_arch = "wasm32"))]
    {
        match rayon::ThreadPoolBuilder::new().num_threads(n.max(1)).build() {
            Ok(pool) => pool.install(job),
            // No threads to be had (a sandbox that forbids them): the calling thread does it all.
            Err(_) => job(),
        }
    }
    #[cfg(target_arch = "wasm32")]
    {
        let _ = n;
        job()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_come_in_order_whatever_the_thread_count() {
        for threads in [1, 2, 5] {
            let squares = with_threads(threads, || map(100, |i| i * i));
            assert_eq!(squares, (0..100).map(|i| i * i).collect::<Vec<_>>());
            let mut data: Vec<usize> = (0..23).collect();
            let sums = with_threads(threads, || {
                map_chunks_mut(&mut data, 5, |i, chunk| {
                    chunk.iter_mut().for_each(|v| *v += 100 * i);
                    chunk.len()
                })
            });
            assert_eq!(sums, vec![5, 5, 5, 5, 3]);
            assert_eq!(data[22], 22 + 400);
        }
    }
}
