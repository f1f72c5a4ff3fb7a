/* Instructions per gt_step on QEMU's mps2-an386 run with -icount shift=0 (each instruction
 * one nanosecond of virtual time): SysTick on the CPU clock counts that time, and a loop of a
 * known instruction count converts its ticks to instructions. Prints the instructions of one
 * gt_step, averaged over STEPS samples at 1 Hz on a slow temperature ramp (every sample is a
 * feature step, so both LSTMs run on each). */
#include <stdint.h>
#include <stdio.h>
#include "gyrotherm_model.h"

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define STEPS 1000L
#define CAL_LOOPS 1000000u

static gt_state state;

static uint32_t ticks_since(uint32_t t0) { return (t0 - SYST_CVR) & 0xFFFFFFu; }

int main(void)
{
    double r, b, k;
    long i;
    uint32_t t0, cal, run;
    SYST_RVR = 0xFFFFFFu;
    SYST_CVR = 0u;
    SYST_CSR = 5u; /* processor clock, enabled, no interrupt */
    /* Two instructions a pass (subs, bne). */
    t0 = SYST_CVR;
    __asm volatile("mov r0, %0\n1:\n\tsubs r0, r0, #1\n\tbne 1b" : : "r"(CAL_LOOPS) : "r0", "cc");
    cal = ticks_since(t0);
    gt_init(&state);
    t0 = SYST_CVR;
    for (i = 0; i < STEPS; i++) {
        gt_step(&state, (double)i, 0.01, 20.0 + 1e-3 * (double)i, &r, &b, &k);
    }
    run = ticks_since(t0);
    printf("%.0f\n", (double)run * (2.0 * CAL_LOOPS / (double)cal) / (double)STEPS);
    return 0;
}
