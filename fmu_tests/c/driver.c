/*
 * Minimal FMI 2.0 Co-Simulation importer for the JetPipeActuator FMU, in plain C.
 *
 * usage: driver EXTRACTED_FMU_DIR GUID
 *
 * dlopen()s binaries/linux64/JetPipeActuator.so, resolves the FMI functions by name with the
 * standard typedefs of fmi2FunctionTypes.h, checks that fmi2DoStep before initialisation
 * returns fmi2Error, then runs 1 s at 1 ms with v_DA = 2.5 V (x_s at its start value) and
 * prints the final F_act, P1 and P2 with 17 significant digits.
 * Exit status 0 on success, 1 on any failure.
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#define VR_V_DA 1u
#define VR_F_ACT 10u
#define VR_P1 11u
#define VR_P2 12u

static int n_errors_logged = 0;

/* A real variadic logger: the message is a printf format with its arguments. */
static void logger(fmi2ComponentEnvironment env, fmi2String instanceName, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    static const char *labels[] = {"OK", "Warning", "Discard", "Error", "Fatal", "Pending"};
    va_list args;
    (void)env;
    if (status >= fmi2Error) n_errors_logged++;
    printf("[%s] [%s] %s: ", (status >= 0 && status <= 5) ? labels[status] : "?",
           category ? category : "", instanceName ? instanceName : "");
    va_start(args, message);
    vprintf(message, args);
    va_end(args);
    printf("\n");
    fflush(stdout);
}

#define RESOLVE(name)                                                          \
    name##TYPE *name = (name##TYPE *)dlsym(lib, #name);                        \
    if (!name) {                                                               \
        fprintf(stderr, "cannot resolve %s: %s\n", #name, dlerror());          \
        return 1;                                                              \
    }

#define CHECK(call)                                                            \
    do {                                                                       \
        fmi2Status s_ = (call);                                                \
        if (s_ != fmi2OK) {                                                    \
            fprintf(stderr, "%s returned %d\n", #call, (int)s_);              \
            return 1;                                                          \
        }                                                                      \
    } while (0)

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s EXTRACTED_FMU_DIR GUID\n", argv[0]);
        return 2;
    }
    const char *dir = argv[1];
    const char *guid = argv[2];

    char path[4096], resources[4200];
    snprintf(path, sizeof path, "%s/binaries/linux64/JetPipeActuator.so", dir);
    snprintf(resources, sizeof resources, "file://%s/resources", dir);

    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen failed: %s\n", dlerror());
        return 1;
    }

    RESOLVE(fmi2GetVersion)
    RESOLVE(fmi2GetTypesPlatform)
    RESOLVE(fmi2Instantiate)
    RESOLVE(fmi2FreeInstance)
    RESOLVE(fmi2SetupExperiment)
    RESOLVE(fmi2EnterInitializationMode)
    RESOLVE(fmi2ExitInitializationMode)
    RESOLVE(fmi2Terminate)
    RESOLVE(fmi2SetReal)
    RESOLVE(fmi2GetReal)
    RESOLVE(fmi2DoStep)

    if (strcmp(fmi2GetVersion(), fmi2Version) != 0) {
        fprintf(stderr, "fmi2GetVersion: %s\n", fmi2GetVersion());
        return 1;
    }
    if (strcmp(fmi2GetTypesPlatform(), fmi2TypesPlatform) != 0) {
        fprintf(stderr, "fmi2GetTypesPlatform: %s\n", fmi2GetTypesPlatform());
        return 1;
    }

    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};

    /* 1. fmi2DoStep before initialisation must fail with fmi2Error */
    fmi2Component c = fmi2Instantiate("early", fmi2CoSimulation, guid, resources, &callbacks, fmi2False, fmi2True);
    if (!c) {
        fprintf(stderr, "fmi2Instantiate returned NULL\n");
        return 1;
    }
    int errors_before = n_errors_logged;
    fmi2Status s = fmi2DoStep(c, 0.0, 1e-3, fmi2True);
    if (s != fmi2Error) {
        fprintf(stderr, "fmi2DoStep before initialisation returned %d, expected fmi2Error\n", (int)s);
        return 1;
    }
    if (n_errors_logged == errors_before) {
        fprintf(stderr, "fmi2DoStep before initialisation logged no error message\n");
        return 1;
    }
    printf("early_doStep_status=%d\n", (int)s);
    fmi2FreeInstance(c);

    /* 2. 1 s at 1 ms with v_DA = 2.5 V */
    c = fmi2Instantiate("driver", fmi2CoSimulation, guid, resources, &callbacks, fmi2False, fmi2False);
    if (!c) {
        fprintf(stderr, "fmi2Instantiate returned NULL\n");
        return 1;
    }
    const fmi2ValueReference vr_in[1] = {VR_V_DA};
    const fmi2Real v_da[1] = {2.5};
    CHECK(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2True, 1.0));
    CHECK(fmi2EnterInitializationMode(c));
    CHECK(fmi2SetReal(c, vr_in, 1, v_da));
    CHECK(fmi2ExitInitializationMode(c));

    const double h = 1e-3;
    double t = 0.0;
    for (int k = 0; k < 1000; k++) {
        CHECK(fmi2DoStep(c, t, h, fmi2True));
        t += h;
    }

    const fmi2ValueReference vr_out[3] = {VR_F_ACT, VR_P1, VR_P2};
    fmi2Real out[3];
    CHECK(fmi2GetReal(c, vr_out, 3, out));
    printf("t=%.17g\nF_act=%.17g\nP1=%.17g\nP2=%.17g\n", t, out[0], out[1], out[2]);

    CHECK(fmi2Terminate(c));
    fmi2FreeInstance(c);
    dlclose(lib);
    return 0;
}
