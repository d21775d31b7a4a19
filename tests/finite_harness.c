/* Test harness of the FMUs' finiteness check (fmubuild/runtime/finite.h), compiled with it by
 * tests/test_runtime_finite.py. */
#include "finite.h"

int all_finite(const double *values, int n) { return rc_all_finite(values, n); }
