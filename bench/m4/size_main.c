/* Size probe: one gt_state and one gt_step call per sample, as in firmware. Built with
 * -DWITH_MODEL for the model's image, -DWITH_IMU for an inertial unit's (one gt_step_imu call
 * per sample), without either for the empty baseline. */
#include <stdint.h>
#if defined(WITH_MODEL) || defined(WITH_IMU)
#include "gyrotherm_model.h"
gt_state state;
#endif
volatile double sample[3];
volatile double result[3];
volatile int status;
#ifdef WITH_IMU
volatile double imu_gyro[GT_AXES], imu_temp[GT_TEMPS], imu_rate[GT_AXES];
volatile int imu_status[GT_AXES];
#endif

int main(void)
{
#if defined(WITH_IMU)
    double g[GT_AXES], c[GT_TEMPS], r[GT_AXES];
    gt_status st[GT_AXES];
    int i;
    gt_init(&state);
    for (;;) {
        for (i = 0; i < GT_AXES; i++) {
            g[i] = imu_gyro[i];
        }
        for (i = 0; i < GT_TEMPS; i++) {
            c[i] = imu_temp[i];
        }
        gt_step_imu(&state, sample[0], g, c, r, st);
        for (i = 0; i < GT_AXES; i++) {
            imu_rate[i] = r[i];
            imu_status[i] = (int)st[i];
        }
    }
#elif defined(WITH_MODEL)
    double r, b, k;
    gt_init(&state);
    for (;;) {
        status = (int)gt_step(&state, sample[0], sample[1], sample[2], &r, &b, &k);
        result[0] = r;
        result[1] = b;
        result[2] = k;
    }
#else
    for (;;) {
        result[0] = sample[0];
        status = 0;
    }
#endif
}
