/* Estimate J from a telemetry CSV through the inertia C API.
 *
 *   estimate [--storage] [--estimator NAME] FILE.csv
 *
 * FILE.csv has the CLI's columns (a header; t, q_x..q_w, rho_x..rho_z, optional
 * tau_x..tau_z and w_x..w_z), as `inertia simulate` writes them; times in seconds.
 *
 * Without --storage the estimator is made on the heap (inertia_estimator_new), with the
 * CLI's default estimator, discrete-momentum. With --storage it is built in a static
 * buffer (inertia_estimator_init): no heap allocation then or at any push; this needs
 * --estimator variational or finite-difference.
 *
 * Prints the status, J, j with σ, at full precision (%.17g). Exit codes: 0 success,
 * 2 bad input or an estimator error (the message on standard error), 3 file unreadable.
 * .ci/c checks the printed j against `inertia estimate --json` on the same file.
 *
 * Built with -DINERTIA_COUNT_ALLOCATIONS and linked with
 * -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc,--wrap=posix_memalign,--wrap=aligned_alloc
 * it also counts the heap allocations the library makes inside the inertia_* calls
 * (creation, pushes, reading the estimate) and prints them; .ci/c requires 0 in caller
 * storage.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "inertia.h"

#ifdef INERTIA_COUNT_ALLOCATIONS
/* Every allocation of the static library goes through these (the linker's --wrap
 * redirects the library's references to malloc & co.). */
static unsigned long allocations;
void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t size);
void *__real_realloc(void *p, size_t n);
int __real_posix_memalign(void **p, size_t align, size_t n);
void *__real_aligned_alloc(size_t align, size_t n);
void *__wrap_malloc(size_t n) { allocations++; return __real_malloc(n); }
void *__wrap_calloc(size_t n, size_t size) { allocations++; return __real_calloc(n, size); }
void *__wrap_realloc(void *p, size_t n) { allocations++; return __real_realloc(p, n); }
int __wrap_posix_memalign(void **p, size_t align, size_t n) {
    allocations++;
    return __real_posix_memalign(p, align, n);
}
void *__wrap_aligned_alloc(size_t align, size_t n) {
    allocations++;
    return __real_aligned_alloc(align, n);
}
#define ALLOCATIONS() allocations
#else
#define ALLOCATIONS() 0UL
#endif

#define MAX_LINE 4096
#define MAX_COLUMNS 64

/* Caller storage for the --storage path: checked against inertia_estimator_size(). */
static _Alignas(64) unsigned char storage[1 << 16];

static void fail_with_message(const char *what, enum InertiaStatus status) {
    char message[1024];
    inertia_last_error_message(message, sizeof message);
    fprintf(stderr, "%s: %s: %s\n", what, inertia_status_name((int32_t)status), message);
}

/* Index of a column in the header, or -1. */
static int column(char names[][64], int n, const char *name) {
    for (int i = 0; i < n; i++) {
        if (strcmp(names[i], name) == 0) {
            return i;
        }
    }
    return -1;
}

/* The name of an estimator id (INERTIA_ESTIMATOR_*, generated from the library's
   registry), or NULL past the last. */
static const char *estimator_name(uint32_t id) {
    switch (id) {
    case INERTIA_ESTIMATOR_VARIATIONAL: return "variational";
    case INERTIA_ESTIMATOR_DISCRETE_MOMENTUM: return "discrete-momentum";
    case INERTIA_ESTIMATOR_FINITE_DIFFERENCE: return "finite-difference";
    case INERTIA_ESTIMATOR_MOMENTUM: return "momentum";
    case INERTIA_ESTIMATOR_EQUATION_ERROR: return "equation-error";
    default: return NULL;
    }
}

static const char *status_word(enum InertiaEstimateStatus s) {
    switch (s) {
    case INERTIA_ESTIMATE_STATUS_DETERMINED: return "determined";
    case INERTIA_ESTIMATE_STATUS_FROM_PRIOR: return "from_prior";
    case INERTIA_ESTIMATE_STATUS_NOT_OBSERVABLE: return "not_observable";
    case INERTIA_ESTIMATE_STATUS_UNCHECKED: return "unchecked";
    case INERTIA_ESTIMATE_STATUS_MODEL_CHECK_FAILED: return "model_check_failed";
    default: return "none";
    }
}

int main(int argc, char **argv) {
    int use_storage = 0;
    const char *path = NULL;
    InertiaSettings settings = inertia_settings_default();
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--storage") == 0) {
            use_storage = 1;
        } else if (strcmp(argv[i], "--estimator") == 0 && i + 1 < argc) {
            const char *name = argv[++i];
            uint32_t k;
            for (k = 1; estimator_name(k) != NULL; k++) {
                if (strcmp(name, estimator_name(k)) == 0) {
                    break;
                }
            }
            if (estimator_name(k) == NULL) {
                fprintf(stderr, "unknown estimator `%s`\n", name);
                return 2;
            }
            settings.estimator = k;
        } else if (argv[i][0] != '-' && path == NULL) {
            path = argv[i];
        } else {
            fprintf(stderr, "usage: %s [--storage] [--estimator NAME] FILE.csv\n", argv[0]);
            return 2;
        }
    }
    if (path == NULL) {
        fprintf(stderr, "usage: %s [--storage] [--estimator NAME] FILE.csv\n", argv[0]);
        return 2;
    }

    InertiaEstimator *est = NULL;
    enum InertiaStatus status;
    unsigned long allocations_at_start = ALLOCATIONS();
    if (use_storage) {
        if (inertia_estimator_size() > sizeof storage || inertia_estimator_align() > 64) {
            fprintf(stderr, "the static storage is too small: %zu bytes aligned to %zu needed\n",
                    inertia_estimator_size(), inertia_estimator_align());
            return 2;
        }
        status = inertia_estimator_init(storage, sizeof storage, &settings, &est);
    } else {
        status = inertia_estimator_new(&settings, &est);
    }
    unsigned long creation_allocations = ALLOCATIONS() - allocations_at_start;
    unsigned long push_allocations = 0;
    (void)creation_allocations; /* printed only when counting */
    if (status != INERTIA_STATUS_OK) {
        fail_with_message("creating the estimator", status);
        return 2;
    }

    FILE *f = fopen(path, "r");
    if (f == NULL) {
        perror(path);
        inertia_estimator_free(est);
        return 3;
    }
    static char line[MAX_LINE];
    static char names[MAX_COLUMNS][64];
    int n_columns = 0;
    if (fgets(line, sizeof line, f) == NULL) {
        fprintf(stderr, "%s: empty file\n", path);
        fclose(f);
        inertia_estimator_free(est);
        return 2;
    }
    for (char *tok = strtok(line, ",\r\n"); tok != NULL && n_columns < MAX_COLUMNS;
         tok = strtok(NULL, ",\r\n")) {
        snprintf(names[n_columns++], sizeof names[0], "%s", tok);
    }
    const char *required[] = {"t", "q_x", "q_y", "q_z", "q_w", "rho_x", "rho_y", "rho_z"};
    int idx[14];
    for (int k = 0; k < 8; k++) {
        idx[k] = column(names, n_columns, required[k]);
        if (idx[k] < 0) {
            fprintf(stderr, "%s:1: no column `%s`\n", path, required[k]);
            fclose(f);
            inertia_estimator_free(est);
            return 2;
        }
    }
    const char *optional[] = {"tau_x", "tau_y", "tau_z", "w_x", "w_y", "w_z"};
    for (int k = 0; k < 6; k++) {
        idx[8 + k] = column(names, n_columns, optional[k]);
    }
    int has_tau = idx[8] >= 0 && idx[9] >= 0 && idx[10] >= 0;
    int has_w = idx[11] >= 0 && idx[12] >= 0 && idx[13] >= 0;

    double values[MAX_COLUMNS];
    long line_number = 1;
    int code = 0;
    while (fgets(line, sizeof line, f) != NULL) {
        line_number++;
        if (line[0] == '\n' || line[0] == '\r') {
            continue;
        }
        int n = 0;
        char *p = line;
        while (n < n_columns) {
            char *end;
            values[n++] = strtod(p, &end);
            if (end == p) {
                fprintf(stderr, "%s:%ld: column %d is not a number\n", path, line_number, n);
                code = 2;
                break;
            }
            p = end;
            if (*p == ',') {
                p++;
            } else {
                break;
            }
        }
        if (code != 0) {
            break;
        }
        if (n != n_columns) {
            fprintf(stderr, "%s:%ld: %d fields, the header has %d\n", path, line_number, n,
                    n_columns);
            code = 2;
            break;
        }
        InertiaSample s;
        memset(&s, 0, sizeof s);
        s.t_s = values[idx[0]];
        for (int k = 0; k < 4; k++) s.q[k] = values[idx[1 + k]];
        for (int k = 0; k < 3; k++) s.rho_nms[k] = values[idx[5 + k]];
        for (int k = 0; k < 3; k++) s.tau_nm[k] = has_tau ? values[idx[8 + k]] : 0.0;
        for (int k = 0; k < 3; k++) s.w_rad_s[k] = has_w ? values[idx[11 + k]] : 0.0;
        s.has_w = (uint8_t)has_w;
        unsigned long before = ALLOCATIONS();
        status = inertia_estimator_push(est, &s);
        push_allocations += ALLOCATIONS() - before;
        if (status != INERTIA_STATUS_OK) {
            char where[512];
            snprintf(where, sizeof where, "%s:%ld", path, line_number);
            fail_with_message(where, status);
            code = 2;
            break;
        }
    }
    if (ferror(f)) {
        perror(path);
        code = 3;
    }
    fclose(f);

    if (code == 0) {
        InertiaEstimate e;
        unsigned long before = ALLOCATIONS();
        inertia_estimator_get(est, &e);
        char reason[512];
        inertia_estimator_reason(est, reason, sizeof reason);
        push_allocations += ALLOCATIONS() - before;
        printf("estimator: %s (%s)\n",
               settings.estimator == INERTIA_ESTIMATOR_DEFAULT ? "discrete-momentum (default)"
                                                                : estimator_name(settings.estimator),
               use_storage ? "caller storage" : "heap");
        printf("samples: %llu, t = %.17g s\n", (unsigned long long)e.samples, e.t_s);
        printf("status: %s%s%s\n", status_word(e.status), reason[0] ? ": " : "", reason);
        if (e.has_answer) {
            printf("J [kg m^2] =\n");
            for (int r = 0; r < 3; r++) {
                printf("  [ %12.6f %12.6f %12.6f ]\n", e.inertia[r][0], e.inertia[r][1],
                       e.inertia[r][2]);
            }
            const char *names6[] = {"J11", "J22", "J33", "J12", "J13", "J23"};
            for (int k = 0; k < 6; k++) {
                printf("j %s %.17g sigma %.17g\n", names6[k], e.j[k], e.sigma[k]);
            }
        } else {
            printf("no answer\n");
        }
#ifdef INERTIA_COUNT_ALLOCATIONS
        printf("allocations: creation %lu, pushes and reads %lu (%llu pushes)\n",
               creation_allocations, push_allocations, (unsigned long long)e.samples);
#endif
    }
    inertia_estimator_free(est);
    return code;
}
