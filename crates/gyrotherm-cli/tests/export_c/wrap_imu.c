/* Test wrapper for the unit differential test: one generated unit model behind a uniquely
 * named runner, so that many units link into one driver. Compile with the model's directory on
 * the include path and -DGT_RUN=run_N -Dgt_init=gt_init_N -Dgt_step_imu=gt_step_imu_N
 * -Dgt_step_imu_bk=gt_step_imu_bk_N -Dgt_coverage_of_axis=gt_coverage_of_axis_N. */
#include <stddef.h>

#include "gyrotherm_model.c"

size_t GT_RUN(size_t n, const double *in, unsigned char *status, double *out);

/* in: n rows of (t, gyro[GT_AXES], temp[GT_TEMPS]); out: per row and axis (rate, bias,
 * scale, coverage, sigma_dph) after the step, coverage the gt_coverage_of_axis value as a
 * double; status per row and axis. gt_step_imu runs on a second state beside
 * gt_step_imu_bk: where its rate or status differs from _bk's, the status is 255; where an
 * axis out of range does not answer GT_NO_VERDICT and NaN, 254. Returns GT_AXES. */
size_t GT_RUN(size_t n, const double *in, unsigned char *status, double *out)
{
    gt_state s, s2;
    size_t i;
    int k;
    const size_t w = 1 + GT_AXES + GT_TEMPS;
    gt_init(&s);
    gt_init(&s2);
    for (i = 0; i < n; i++) {
        double rate[GT_AXES], bias[GT_AXES], scale[GT_AXES], rate2[GT_AXES];
        gt_status st[GT_AXES], st2[GT_AXES];
        double sigma = 0.0;
        int beyond;
        const double *row = in + w * i;
        gt_step_imu_bk(&s, row[0], row + 1, row + 1 + GT_AXES, rate, st, bias, scale);
        gt_step_imu(&s2, row[0], row + 1, row + 1 + GT_AXES, rate2, st2);
        for (k = 0; k < GT_AXES; k++) {
            size_t j = (size_t)GT_AXES * i + (size_t)k;
            int same = st[k] == st2[k] && memcmp(&rate[k], &rate2[k], sizeof rate[k]) == 0;
            gt_coverage c = gt_coverage_of_axis(&s, k, &sigma);
            status[j] = same ? (unsigned char)st[k] : 255u;
            out[5 * j] = rate[k];
            out[5 * j + 1] = bias[k];
            out[5 * j + 2] = scale[k];
            out[5 * j + 3] = (double)c;
            out[5 * j + 4] = sigma;
        }
        beyond = (int)i % 2 == 0 ? GT_AXES : -1;
        if (gt_coverage_of_axis(&s, beyond, &sigma) != GT_NO_VERDICT || !isnan(sigma)) {
            status[(size_t)GT_AXES * i] = 254u;
        }
    }
    return GT_AXES;
}
