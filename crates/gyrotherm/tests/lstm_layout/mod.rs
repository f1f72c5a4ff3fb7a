//! The LSTM's flat parameter layout, written out for the tests from the documented layout
//! (`LstmParams`), independently of the library's own (which is private).

use gyrotherm::nn::LstmParams;

/// Flat parameter vector in PyTorch order (w_ih, w_hh, b_ih, b_hh, w_out, b_out), written out
/// here from the documented layout (`LstmParams`), independently of the library's own.
pub fn flatten(p: &LstmParams) -> Vec<f64> {
    let mut v = Vec::new();
    for t in [&p.w_ih, &p.w_hh, &p.b_ih, &p.b_hh, &p.w_out] {
        v.extend_from_slice(t);
    }
    v.push(p.b_out);
    v
}

/// Inverse of [`flatten`].
pub fn unflatten(theta: &[f64], input_size: usize, hidden_size: usize) -> LstmParams {
    let (i, h) = (input_size, hidden_size);
    let mut at = 0;
    let mut take = |n: usize| {
        let s = theta[at..at + n].to_vec();
        at += n;
        s
    };
    let (w_ih, w_hh, b_ih, b_hh, w_out) = (
        take(4 * h * i),
        take(4 * h * h),
        take(4 * h),
        take(4 * h),
        take(h),
    );
    LstmParams {
        input_size,
        hidden_size,
        w_ih,
        w_hh,
        b_ih,
        b_hh,
        w_out,
        b_out: theta[at],
    }
}
