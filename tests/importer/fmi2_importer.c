/* A small FMI 2.0 Co-Simulation importer of our own (tests/test_platforms.py): it loads an FMU's
 * shared library (dlopen, or LoadLibrary on Windows), instantiates it for Co-Simulation, sets
 * values, steps a fixed scenario and prints the chosen variables after every step with %.17g, so
 * that the binaries of several platforms (run natively, under wine or under qemu-user) can be
 * compared digit for digit. Compiled for each target with zig's C compiler against the FMI 2.0
 * headers the FMU ships in sources/; it links no math library of its own.
 *
 * usage: fmi2_importer LIBRARY GUID PREFIX STEPS STEP_SIZE [COMMAND ...]
 *   PREFIX      "-" for the fmi2 names as they are, else a prefix (a library of source FMUs
 *               compiled with FMI2_FUNCTION_PREFIX)
 *   commands:   set VR VALUE         fmi2SetReal before initialization
 *               at STEP VR VALUE     fmi2SetReal before the step numbered STEP (0-based)
 *               out VR               a variable to print after each step
 * output: one line per step: the time, then the values of the "out" variables; exit 0 when every
 * call returned fmi2OK. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2FunctionTypes.h"

#ifdef _WIN32
#include <windows.h>
typedef HMODULE Library;
static Library open_library(const char *path) { return LoadLibraryA(path); }
static void *symbol(Library library, const char *name) { return (void *)GetProcAddress(library, name); }
static void close_library(Library library) { FreeLibrary(library); }
static const char *load_error(void) { return "LoadLibrary failed"; }
#else
#include <dlfcn.h>
typedef void *Library;
static Library open_library(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *symbol(Library library, const char *name) { return dlsym(library, name); }
static void close_library(Library library) { dlclose(library); }
static const char *load_error(void) { return dlerror(); }
#endif

#define MAX_COMMANDS 64

typedef struct {
    long step;  /* -1: before initialization */
    fmi2ValueReference vr;
    fmi2Real value;
} Assignment;

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    va_list args;
    (void)env;
    va_start(args, message);
    fprintf(stderr, "[%s %d %s] ", instance ? instance : "?", (int)status, category ? category : "");
    vfprintf(stderr, message, args);
    fputc('\n', stderr);
    va_end(args);
}

static const char *prefix = "";

static void *function(Library library, const char *name) {
    char full[256];
    void *address;
    snprintf(full, sizeof full, "%s%s", prefix, name);
    address = symbol(library, full);
    if (!address) {
        fprintf(stderr, "fmi2_importer: %s not found in the library\n", full);
        exit(3);
    }
    return address;
}

static int check(fmi2Status status, const char *what) {
    if (status != fmi2OK) {
        fprintf(stderr, "fmi2_importer: %s returned status %d\n", what, (int)status);
        return 1;
    }
    return 0;
}

int main(int argc, char **argv) {
    Assignment assignments[MAX_COMMANDS];
    fmi2ValueReference outputs[MAX_COMMANDS];
    fmi2Real values[MAX_COMMANDS];
    size_t n_assignments = 0, n_outputs = 0, i;
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    Library library;
    fmi2Component instance;
    long steps, step;
    double h, t = 0.0;
    int a, failed = 0;

    if (argc < 6) {
        fprintf(stderr, "usage: fmi2_importer LIBRARY GUID PREFIX STEPS STEP_SIZE [set VR VALUE | at STEP VR VALUE | "
                        "out VR]...\n");
        return 2;
    }
    if (strcmp(argv[3], "-") != 0) prefix = argv[3];
    steps = strtol(argv[4], NULL, 10);
    h = strtod(argv[5], NULL);
    for (a = 6; a < argc;) {
        if (n_assignments >= MAX_COMMANDS || n_outputs >= MAX_COMMANDS) return 2;
        if (strcmp(argv[a], "set") == 0 && a + 2 < argc) {
            assignments[n_assignments].step = -1;
            assignments[n_assignments].vr = (fmi2ValueReference)strtoul(argv[a + 1], NULL, 10);
            assignments[n_assignments++].value = strtod(argv[a + 2], NULL);
            a += 3;
        } else if (strcmp(argv[a], "at") == 0 && a + 3 < argc) {
            assignments[n_assignments].step = strtol(argv[a + 1], NULL, 10);
            assignments[n_assignments].vr = (fmi2ValueReference)strtoul(argv[a + 2], NULL, 10);
            assignments[n_assignments++].value = strtod(argv[a + 3], NULL);
            a += 4;
        } else if (strcmp(argv[a], "out") == 0 && a + 1 < argc) {
            outputs[n_outputs++] = (fmi2ValueReference)strtoul(argv[a + 1], NULL, 10);
            a += 2;
        } else {
            fprintf(stderr, "fmi2_importer: cannot read the command at %s\n", argv[a]);
            return 2;
        }
    }

    library = open_library(argv[1]);
    if (!library) {
        fprintf(stderr, "fmi2_importer: cannot load %s: %s\n", argv[1], load_error());
        return 3;
    }
    {
        fmi2GetVersionTYPE *get_version = (fmi2GetVersionTYPE *)function(library, "fmi2GetVersion");
        fmi2InstantiateTYPE *instantiate = (fmi2InstantiateTYPE *)function(library, "fmi2Instantiate");
        fmi2SetupExperimentTYPE *setup = (fmi2SetupExperimentTYPE *)function(library, "fmi2SetupExperiment");
        fmi2EnterInitializationModeTYPE *enter =
            (fmi2EnterInitializationModeTYPE *)function(library, "fmi2EnterInitializationMode");
        fmi2ExitInitializationModeTYPE *exit_init =
            (fmi2ExitInitializationModeTYPE *)function(library, "fmi2ExitInitializationMode");
        fmi2SetRealTYPE *set_real = (fmi2SetRealTYPE *)function(library, "fmi2SetReal");
        fmi2GetRealTYPE *get_real = (fmi2GetRealTYPE *)function(library, "fmi2GetReal");
        fmi2DoStepTYPE *do_step = (fmi2DoStepTYPE *)function(library, "fmi2DoStep");
        fmi2TerminateTYPE *terminate = (fmi2TerminateTYPE *)function(library, "fmi2Terminate");
        fmi2FreeInstanceTYPE *free_instance = (fmi2FreeInstanceTYPE *)function(library, "fmi2FreeInstance");

        if (strcmp(get_version(), "2.0") != 0) {
            fprintf(stderr, "fmi2_importer: fmi2GetVersion() is %s\n", get_version());
            return 3;
        }
        instance = instantiate("importer", fmi2CoSimulation, argv[2], NULL, &callbacks, fmi2False, fmi2False);
        if (!instance) {
            fprintf(stderr, "fmi2_importer: fmi2Instantiate failed\n");
            return 3;
        }
        for (i = 0; i < n_assignments; i++)
            if (assignments[i].step < 0) failed |= check(set_real(instance, &assignments[i].vr, 1, &assignments[i].value),
                                                         "fmi2SetReal");
        failed |= check(setup(instance, fmi2False, 0.0, 0.0, fmi2False, 0.0), "fmi2SetupExperiment");
        failed |= check(enter(instance), "fmi2EnterInitializationMode");
        failed |= check(exit_init(instance), "fmi2ExitInitializationMode");
        for (step = 0; step < steps && !failed; step++) {
            for (i = 0; i < n_assignments; i++)
                if (assignments[i].step == step)
                    failed |= check(set_real(instance, &assignments[i].vr, 1, &assignments[i].value), "fmi2SetReal");
            failed |= check(do_step(instance, t, h, fmi2True), "fmi2DoStep");
            t = (double)(step + 1) * h;
            failed |= check(get_real(instance, outputs, n_outputs, values), "fmi2GetReal");
            printf("%.17g", t);
            for (i = 0; i < n_outputs; i++) printf(" %.17g", values[i]);
            printf("\n");
        }
        failed |= check(terminate(instance), "fmi2Terminate");
        free_instance(instance);
    }
    close_library(library);
    return failed ? 1 : 0;
}
