/*
 * Bare-metal start-up for running test_api.c on QEMU's mps2-an386 (Cortex-M4F), ci/c_api.sh:
 * the vector table, a reset handler that enables the FPU, zeroes .bss, opens newlib's
 * semihosting streams (rdimon) and calls main, and fault handlers that report and exit.
 * Memory map: m4.ld. Output and the exit code go to the host through semihosting.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

extern int main(void);
extern void initialise_monitor_handles(void);
extern void _exit(int status);

extern uint32_t __bss_start__[], __bss_end__[], __stack_top[];

void reset_c(void);

/* The FPU must be on before the first floating-point instruction (-mfloat-abi=hard). */
__attribute__((naked, noreturn)) void Reset_Handler(void) {
    __asm__ volatile("ldr r0, =0xE000ED88\n" /* CPACR */
                     "ldr r1, [r0]\n"
                     "orr r1, r1, #(0xF << 20)\n" /* CP10, CP11: full access */
                     "str r1, [r0]\n"
                     "dsb\n"
                     "isb\n"
                     "b reset_c\n");
}

void reset_c(void) {
    for (uint32_t *p = __bss_start__; p < __bss_end__; p++) {
        *p = 0;
    }
    initialise_monitor_handles();
    exit(main());
}

/* newlib's exit() runs the fini array through _fini; there are no C++ destructors here. */
void _init(void) {}
void _fini(void) {}

static void fault(void) {
    /* No printf here: the fault may have hit anywhere. Exit code 3 tells the script. */
    _exit(3);
}

/* The library's panic hook (feature ffi-panic-handler): report, then exit with code 4. */
void sfs_panic_hook(const char *file, size_t file_len, uint32_t line) {
    printf("PANIC in the library at %.*s:%lu\n", (int)file_len, file, (unsigned long)line);
    _exit(4);
}

__attribute__((section(".isr_vector"), used)) static const uintptr_t vectors[16] = {
    (uintptr_t)__stack_top,
    (uintptr_t)Reset_Handler,
    (uintptr_t)fault, /* NMI */
    (uintptr_t)fault, /* HardFault */
    (uintptr_t)fault, /* MemManage */
    (uintptr_t)fault, /* BusFault */
    (uintptr_t)fault, /* UsageFault */
};
