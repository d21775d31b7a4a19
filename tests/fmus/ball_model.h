/* The bouncing ball of the engine's test FMUs (ball2.c: FMI 2.0 Model Exchange; ball3.c: FMI 3.0
 * Co-Simulation and Model Exchange): the equations once, each interface's calls around them.
 *
 *   der(h) = v,  der(v) = a - g           (h: height [m], v: velocity [m/s], a: input [m/s2])
 *   frozen (a discrete input, ball2 only): the ball is held where it is (both derivatives 0)
 *   state event  h = 0 falling: v := -e v (count += 1); below V_REST the ball rests on the floor
 *   time event   t = tSwitch: late := true
 *   maxBounces > 0: the simulation ends at that bounce.
 */
#ifndef BALL_MODEL_H
#define BALL_MODEL_H

#include <math.h>

/* m/s: a bounce slower than this leaves the ball resting on the floor (no Zeno chattering). */
#define V_REST 0.1

typedef struct {
    double time;        /* s */
    double h, v;        /* m, m/s: the states */
    double g, e;        /* m/s2 gravity, 1 coefficient of restitution */
    double a;           /* m/s2: input, an upward acceleration */
    double t_switch;    /* s: the time event */
    int count, max_bounces, late, resting, terminated, frozen;
} Ball;

static inline void ball_defaults(Ball *b) {
    b->time = 0.0; b->h = 1.0; b->v = 0.0; b->g = 9.81; b->e = 0.7; b->a = 0.0; b->t_switch = 0.5;
    b->count = 0; b->max_bounces = 0; b->late = 0; b->resting = 0; b->terminated = 0; b->frozen = 0;
}

/* m/s2: the acceleration (none while resting, unless the input lifts the ball). */
static inline double ball_acceleration(const Ball *b) {
    double acceleration = b->a - b->g;
    if (b->frozen) return 0.0;
    return b->resting && acceleration <= 0.0 ? 0.0 : acceleration;
}

/* m/s: the rate of the height (none while resting or frozen). */
static inline double ball_height_rate(const Ball *b) { return b->resting || b->frozen ? 0.0 : b->v; }

/* The event indicator: the height (positive in flight; a resting ball has none to cross). */
static inline double ball_indicator(const Ball *b) { return b->resting ? 1.0 : b->h; }

/* s: the next time event (INFINITY: none). */
static inline double ball_next_time_event(const Ball *b) { return b->late ? INFINITY : b->t_switch; }

/* The event at the current time: a bounce where the ball is at the floor falling, the time
 * event where due. Returns whether the simulation ends here. */
static inline int ball_event(Ball *b) {
    if (!b->resting && b->h <= 0.0 && b->v < 0.0) {
        b->h = 0.0;
        b->v = -b->e * b->v;
        b->count += 1;
        if (b->v < V_REST) { b->v = 0.0; b->resting = 1; }
        if (b->max_bounces > 0 && b->count >= b->max_bounces) b->terminated = 1;
    }
    if (b->resting && b->a - b->g > 0.0) b->resting = 0;
    if (!b->late && b->time >= b->t_switch - 1e-12) b->late = 1;
    return b->terminated;
}

/* s: the time from now to the next impact (INFINITY: none), from the exact free flight. */
static inline double ball_time_to_impact(const Ball *b) {
    double acceleration = ball_acceleration(b);
    if (b->resting) return INFINITY;
    if (b->h <= 0.0 && b->v < 0.0) return 0.0;
    if (acceleration == 0.0) return b->v < 0.0 ? -b->h / b->v : INFINITY;
    /* h + v t + acceleration t^2 / 2 = 0, the first positive root */
    double discriminant = b->v * b->v - 2.0 * acceleration * b->h;
    if (discriminant < 0.0) return INFINITY;
    double root = sqrt(discriminant);
    double t1 = (-b->v - root) / acceleration, t2 = (-b->v + root) / acceleration;
    double first = INFINITY;
    if (t1 > 1e-14) first = t1;
    if (t2 > 1e-14 && t2 < first) first = t2;
    return first;
}

/* Exact free flight over dt [s] (no event inside). */
static inline void ball_fly(Ball *b, double dt) {
    double acceleration = ball_acceleration(b);
    b->h += b->v * dt + 0.5 * acceleration * dt * dt;
    b->v += acceleration * dt;
    b->time += dt;
}

/* Co-Simulation: from the current time over dt [s], exactly (flights, bounces, the time event).
 * Returns whether the simulation ended inside (b->time is then where). */
static inline int ball_advance(Ball *b, double dt) {
    double end = b->time + dt;
    for (int events = 0; events < 100000 && b->time < end; events++) {
        double left = end - b->time;
        double impact = ball_time_to_impact(b);
        double switch_in = b->late ? INFINITY : fmax(b->t_switch - b->time, 0.0);
        double leg = fmin(left, fmin(impact, switch_in));
        ball_fly(b, leg);
        if (leg == impact) b->h = 0.0;
        if (ball_event(b)) return 1;
        if (leg == left) break;
    }
    b->time = end;
    return 0;
}

#endif
