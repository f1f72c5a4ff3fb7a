//! Work split over threads, one per item: the axes of a unit, the sensors of its log.

/// `f` of each index `0..n`, each on a thread of its own, the results in index order. A panic
/// on a thread is resumed on the caller's.
pub(crate) fn on_threads<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let f = &f;
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..n).map(|k| scope.spawn(move || f(k))).collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    })
}

#[cfg(test)]
mod tests {
    /// Results come back in index order whatever order the threads finish in.
    #[test]
    fn results_are_in_index_order() {
        let out = super::on_threads(8, |k| {
            std::thread::sleep(std::time::Duration::from_millis((8 - k as u64) * 2));
            k * k
        });
        assert_eq!(out, (0..8).map(|k| k * k).collect::<Vec<_>>());
    }
}
