/* Test driver for the generated C model: reads a gyrotherm CSV log (the file named by the
 * first argument, else stdin; header with
 * time_s, gyro_dps, temp_c), calls gt_step per data line and prints
 * `status,rate_dps,bias_dps,scale,coverage,sigma_dph` per line (%.17g, so the doubles
 * round-trip; rate empty when the status is invalid; coverage and sigma_dph from
 * gt_coverage_of, both empty without a verdict or a map, as the stream writes them). A field
 * that is not a number is read as NaN. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gyrotherm_model.h"

#define MAX_LINE 65536
#define MAX_FIELDS 256

static int split(char *line, char **fields)
{
    int n = 0;
    char *p = line;
    fields[n++] = p;
    while (*p != '\0' && n < MAX_FIELDS) {
        if (*p == ',') {
            *p = '\0';
            fields[n++] = p + 1;
        }
        p++;
    }
    return n;
}

static double number(const char *s)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s) {
        return strtod("nan", NULL);
    }
    return v;
}

int main(int argc, char **argv)
{
    FILE *in = stdin;
    static char line[MAX_LINE];
    char *fields[MAX_FIELDS];
    int ti = -1, gi = -1, ci = -1, n, i;
    gt_state s;
    static const char *names[] = {"ok", "held", "degraded", "invalid"};
    static const char *cover[] = {"inside", "edge", "outside"};
    if (argc > 1 && (in = fopen(argv[1], "r")) == NULL) {
        fprintf(stderr, "driver: cannot open %s\n", argv[1]);
        return 2;
    }
    if (fgets(line, sizeof line, in) == NULL) {
        return 2;
    }
    line[strcspn(line, "\r\n")] = '\0';
    n = split(line, fields);
    for (i = 0; i < n; i++) {
        if (strcmp(fields[i], "time_s") == 0) {
            ti = i;
        } else if (strcmp(fields[i], "gyro_dps") == 0) {
            gi = i;
        } else if (strcmp(fields[i], "temp_c") == 0) {
            ci = i;
        }
    }
    if (ti < 0 || gi < 0 || ci < 0) {
        fprintf(stderr, "driver: header lacks time_s, gyro_dps or temp_c\n");
        return 2;
    }
    gt_init(&s);
    printf("status,gyro_comp_dps,bias_dps,scale,coverage,sigma_dph\n");
    while (fgets(line, sizeof line, in) != NULL) {
        double rate, bias, scale, sigma;
        gt_status st;
        gt_coverage cv;
        line[strcspn(line, "\r\n")] = '\0';
        if (line[0] == '\0' || line[0] == '#') {
            continue;
        }
        n = split(line, fields);
        if (n <= ti || n <= gi || n <= ci) {
            fprintf(stderr, "driver: short line\n");
            return 2;
        }
        st = gt_step(&s, number(fields[ti]), number(fields[gi]), number(fields[ci]), &rate,
                     &bias, &scale);
        if (st == GT_INVALID) {
            printf("%s,,%.17g,%.17g", names[st], bias, scale);
        } else {
            printf("%s,%.17g,%.17g,%.17g", names[st], rate, bias, scale);
        }
        cv = gt_coverage_of(&s, &sigma);
        if (cv == GT_INSIDE || cv == GT_EDGE || cv == GT_OUTSIDE) {
            printf(",%s,%.17g\n", cover[cv], sigma);
        } else {
            printf(",,\n");
        }
    }
    return 0;
}
