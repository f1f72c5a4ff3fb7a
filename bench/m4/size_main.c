/* Size probe: one gt_state and one gt_step call per sample, as in firmware. Built with
 * -DWITH_MODEL for the model's image, without for the empty baseline. */
#include <stdint.h>
#ifdef WITH_MODEL
#include "gyrotherm_model.h"
gt_state state;
#endif
volatile double sample[3];
volatile double result[3];
volatile int status;

int main(void)
{
#ifdef WITH_MODEL
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
