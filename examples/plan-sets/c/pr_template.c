/*
 * Propulsion (PR) in the shape of the RCS methodology's C controller
 * template (NIST 1992, Appendices A and C): Global Memory is a struct of
 * buffers; each cycle copies its interface buffers in (pre-process), checks
 * for a new command, runs the state table of the active command as an
 * if / else-if chain (the paper's ST_BGN / ST / THEN / DEFAULT macros), and
 * copies its buffers out (post-process). Written for rcsc's benchmark; the
 * harness plays the turbine and the ship through the pr_c_* functions.
 */
#include <string.h>

#define COPY_BUFFER(dst, src, size) memcpy((dst), (src), (size))
#define ST_BGN if (
#define THEN ) {
#define ST } else if (
#define DEFAULT } else {
#define ST_END }

enum { NOP = 0, S1 = 1, S2 = 2 };
enum { PR_NOT_READY = 0, PR_EXECUTING = 1, PR_DONE = 2, PR_ERROR = 3, PR_AT_GOAL = 4 };
enum { PR_INIT = 0, PR_HALT = 1, PR_AHEAD = 2 };
enum { TB_INIT = 0, TB_HALT = 1, TB_AHEAD = 2, TB_STOP = 3 };
enum { TB_DONE = 2 };
enum { MOVING_AHEAD = 0, STOPPED = 1, MOVING_BACK = 2 };
enum { BELOW_SPEED, AT_SPEED, ABOVE_SPEED };

typedef struct { unsigned command_num; unsigned command; double speed; } PR_COMMAND;
typedef struct { unsigned echo_num; unsigned status; unsigned state; } PR_STATUS;
typedef struct { unsigned command_num; unsigned command; double rpm; } TB_COMMAND;
typedef struct { unsigned echo_num; unsigned status; } TB_STATUS;
typedef struct { int direction; double speed; } SHIP;
/* PR's status data, published every cycle beside its status. */
typedef struct { double ordered_rpm; double ship_speed; } PR_STATUS_FIELDS;

typedef struct {
    PR_COMMAND pr_ci;
    PR_STATUS pr_so;
    PR_STATUS_FIELDS pr_sf;
    TB_COMMAND tb_ci;
    TB_STATUS tb_so;
    SHIP ship;
} GLOBAL_MEMORY;

static GLOBAL_MEMORY G_MEM;
static GLOBAL_MEMORY *G = &G_MEM;

/* PR's local copies of its interface buffers. */
static PR_COMMAND pr_ci;
static PR_STATUS pr_so;
static PR_STATUS_FIELDS pr_sf;
static TB_COMMAND tb_co;
static TB_STATUS tb_si;
static SHIP ship;
static int pr_cur_state;
static int new_command;
static double prop_speed;
static int sub_speed_status;

static void calc_fwd_prop_speed(void) { prop_speed = pr_ci.speed * 10.0; }

static void calc_speed_status(void)
{
    if (ship.speed < pr_ci.speed - 0.5)
        sub_speed_status = BELOW_SPEED;
    else if (ship.speed > pr_ci.speed + 0.5)
        sub_speed_status = ABOVE_SPEED;
    else
        sub_speed_status = AT_SPEED;
}

static void pr_pre_process(void)
{
    COPY_BUFFER(&pr_ci, &(G->pr_ci), sizeof(PR_COMMAND));
    COPY_BUFFER(&tb_si, &(G->tb_so), sizeof(TB_STATUS));
    COPY_BUFFER(&ship, &(G->ship), sizeof(SHIP));
    /* A DONE echoing an older command counts as still executing. */
    if (tb_si.echo_num != tb_co.command_num)
        tb_si.status = 1;
}

/* Every cycle, before the decision: the ship speed as read. */
static void pr_every_cycle_pre(void) { pr_sf.ship_speed = ship.speed; }

static void pr_check_if_new_command(void)
{
    if (pr_ci.command_num != pr_so.echo_num) {
        new_command = 1;
        pr_so.echo_num = pr_ci.command_num;
        pr_so.status = PR_EXECUTING;
        pr_cur_state = NOP;
    } else {
        new_command = 0;
    }
}

static void pr_ahead(void)
{
    calc_speed_status();
    ST_BGN
        new_command && (ship.direction == MOVING_AHEAD || ship.direction == STOPPED)
        THEN
            pr_cur_state = S1;
            calc_fwd_prop_speed();
            tb_co.command = TB_AHEAD;
            tb_co.command_num++;
            tb_co.rpm = prop_speed;
    ST
        new_command && ship.direction == MOVING_BACK
        THEN
            pr_cur_state = S2;
            tb_co.command = TB_STOP;
            tb_co.command_num++;
    ST
        pr_cur_state == S2 && tb_si.status == TB_DONE
        THEN
            pr_cur_state = S1;
            calc_fwd_prop_speed();
            tb_co.command = TB_AHEAD;
            tb_co.command_num++;
            tb_co.rpm = prop_speed;
    ST
        pr_cur_state == S1 && tb_si.status == TB_DONE && sub_speed_status == BELOW_SPEED
        THEN
            ++prop_speed;
            tb_co.command = TB_AHEAD;
            tb_co.command_num++;
            tb_co.rpm = prop_speed;
    ST
        pr_cur_state == S1 && tb_si.status == TB_DONE && sub_speed_status == ABOVE_SPEED
        THEN
            --prop_speed;
            tb_co.command = TB_AHEAD;
            tb_co.command_num++;
            tb_co.rpm = prop_speed;
    ST
        pr_cur_state == S1 && tb_si.status == TB_DONE && sub_speed_status == AT_SPEED
        THEN
            pr_so.status = PR_AT_GOAL;
    DEFAULT
    ST_END
}

static void pr_decision_process(void)
{
    switch (pr_ci.command) {
    case PR_AHEAD:
        pr_ahead();
        break;
    default:
        break;
    }
}

static void pr_post_process(void)
{
    pr_so.state = (unsigned)pr_cur_state;
    pr_sf.ordered_rpm = prop_speed;
    COPY_BUFFER(&(G->pr_so), &pr_so, sizeof(PR_STATUS));
    COPY_BUFFER(&(G->pr_sf), &pr_sf, sizeof(PR_STATUS_FIELDS));
    COPY_BUFFER(&(G->tb_ci), &tb_co, sizeof(TB_COMMAND));
}

/* One control cycle of PR. */
void pr_c_controller(void)
{
    pr_pre_process();
    pr_check_if_new_command();
    pr_every_cycle_pre();
    pr_decision_process();
    pr_post_process();
}

/* Harness: reset everything. */
void pr_c_reset(void)
{
    memset(G, 0, sizeof(*G));
    memset(&pr_ci, 0, sizeof(pr_ci));
    memset(&pr_so, 0, sizeof(pr_so));
    memset(&pr_sf, 0, sizeof(pr_sf));
    memset(&tb_co, 0, sizeof(tb_co));
    memset(&tb_si, 0, sizeof(tb_si));
    memset(&ship, 0, sizeof(ship));
    pr_cur_state = NOP;
    new_command = 0;
    prop_speed = 0.0;
}

/* Harness as PR's supervisor: AHEAD at a speed. */
void pr_c_command_ahead(double speed)
{
    G->pr_ci.command_num++;
    G->pr_ci.command = PR_AHEAD;
    G->pr_ci.speed = speed;
}

/* Harness as the turbine and the ship: TB answers DONE to its last command. */
void pr_c_world(double ship_speed)
{
    G->tb_so.echo_num = G->tb_ci.command_num;
    G->tb_so.status = TB_DONE;
    G->ship.direction = MOVING_AHEAD;
    G->ship.speed = ship_speed;
}

/* Harness: PR's state, status and the RPM last sent to TB. */
unsigned pr_c_state(void) { return G->pr_so.state; }
unsigned pr_c_status(void) { return G->pr_so.status; }
double pr_c_rpm(void) { return G->tb_ci.rpm; }
/* Harness: PR's status fields. */
double pr_c_ordered_rpm(void) { return G->pr_sf.ordered_rpm; }
double pr_c_ship_speed(void) { return G->pr_sf.ship_speed; }
