/* Test wrapper for the differential test: one generated model behind a uniquely named
 * runner, so that many models link into one driver. Compile with the model's directory on the
 * include path and -DGT_RUN=run_N -Dgt_init=gt_init_N -Dgt_step=gt_step_N -Dgt_coverage_of=gt_coverage_of_N (each model's
 * gt_state and static helpers stay inside its own translation unit). */
#include <stddef.h>

#include "gyrotherm_model.c"

void GT_RUN(size_t n, const double *in, unsigned char *status, double *out);

/* in: n (time_s, gyro_dps, temp_c) triples; out: n (rate_dps, bias_dps, scale, coverage,
 * sigma_dph) quintuples, coverage the gt_coverage value as a double. */
void GT_RUN(size_t n, const double *in, unsigned char *status, double *out)
{
    gt_state s;
    size_t i;
    gt_init(&s);
    for (i = 0; i < n; i++) {
        double r, b, k, sigma;
        gt_coverage c;
        status[i] = (unsigned char)gt_step(&s, in[3 * i], in[3 * i + 1], in[3 * i + 2], &r,
                                           &b, &k);
        c = gt_coverage_of(&s, &sigma);
        out[5 * i] = r;
        out[5 * i + 1] = b;
        out[5 * i + 2] = k;
        out[5 * i + 3] = (double)c;
        out[5 * i + 4] = sigma;
    }
}
