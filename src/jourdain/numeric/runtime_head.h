/* jourdain's recursion engines sized at run time (numeric/runtime_engine.py): the text of
 * planar_engine.h or recursive_engine.h compiled once into the integrator's library
 * (integrator_c.UNITS), with the model's sizes and tables read from a context (jd_rt) instead
 * of the constants and static arrays of a model's own unit, and its jd_local (the generated
 * per-joint code) evaluated by the interpreter (interpreter.h), so that a recursion-path
 * model's first run needs no compiler.
 *
 * Before the engine's text, this head makes the work's arrays pointers into one allocation
 * (JD_ARRAY, with the context in each work as JD_RT_FIELD) and every size and table a field of
 * that context, read through the work W that each of the engine's functions takes (JD_P is
 * W->rt->p). The engine's arithmetic is unchanged: the same operations on the same operands in
 * the same order (no flag of toolchain.CFLAGS reorders or contracts them, and a loop whose
 * bound is read at run time does the same ones), so the numbers are a model library's to the
 * bit. JD_ABA is 1: its articulated bodies are compiled, and with own_only = 0 its recursion
 * does what a library without them does; JD_FULL, JD_QBAR and the engines' entry points
 * (JD_RUNTIME) are left out: runtime_engine.h has its own. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    int p, f, nc, nl, cols;     /* bodies, coordinates, Jacobian columns, local numbers, the
                                   columns' place in them (the unit's JD_P … JD_COLS) */
    int written_out;            /* LDLᵀ written out (integrator_ldl.py) or the loop */
    const int *parent, *col_start, *col_coord;  /* jd_parent, jd_col_start, jd_col_coord */
    const void *local;          /* jd_local's program (interpreter.h's jd_interp) */
    long n_reg;                 /* its registers */
} jd_rt;

#define JD_RUNTIME 1
#define JD_ABA 1
#define JD_FULL 0
#define JD_QBAR 0
#define JD_BODY 40  /* recursive.BODY_BLOCK (runtime_engine.py checks the unit's) */
#define JD_ARRAY(type, name, n) type *name;
#define JD_RT_FIELD const jd_rt *rt;
#define JD_P (W->rt->p)
#define JD_F (W->rt->f)
#define JD_NC (W->rt->nc)
#define JD_COLS (W->rt->cols)
#define jd_parent (W->rt->parent)
#define jd_col_start (W->rt->col_start)
#define jd_col_coord (W->rt->col_coord)
