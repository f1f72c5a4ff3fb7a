/* Minimal Cortex-M4F start-up for QEMU's mps2-an386: vector table, FPU on, then newlib's
 * semihosting start (rdimon), which zeroes .bss, sets up stdio and argv and calls main. */
#include <stdint.h>

extern void _start(void);
extern uint32_t __stack;
void reset_handler(void);

static void fault(void)
{
    for (;;) {
    }
}

__attribute__((section(".vectors"), used)) static void (*const vectors[16])(void) = {
    (void (*)(void))(&__stack), reset_handler, fault, fault, fault, fault, fault, 0, 0, 0, 0,
    fault, fault, 0, fault, fault,
};

void reset_handler(void)
{
    /* CPACR: full access to CP10 and CP11 (the FPU). */
    *(volatile uint32_t *)0xE000ED88u |= 0xFu << 20;
    __asm volatile("dsb\n\tisb");
    _start();
    fault();
}
