#!/usr/bin/env python3
"""How often the screw verdict turns red by chance: two codes whose mean flows are equal,
judged by the verdict's rule (|a - b| > 2 (SE_a + SE_b), each side's SE its runs' block
errors combined, or with several seeds its seeds' spread if larger; docs/validation.md,
"Screw cases"). Each run's flow scatters with standard deviation `ratio` around the mean,
and its block-average standard error from 2 blocks is |N(0, 1)| (one degree of freedom,
mean square 1). ratio = 1: the block error is an unbiased estimate of the run's noise;
ratio = 0.66: the Hertz screw at 100 rpm, where the seeds scatter with 0.058 kg/s and the
runs' block errors have a root mean square of 0.088 kg/s (reports/contact-law/NOTE.md).

usage: python3 reports/screw_three_codes/false_red.py [SAMPLES]
"""
import random
import statistics
import sys


def side(seeds, ratio, rng):
    flows = [rng.gauss(0.0, ratio) for _ in range(seeds)]
    errors = [abs(rng.gauss(0.0, 1.0)) for _ in range(seeds)]
    mean = sum(flows) / seeds
    se = sum(e * e for e in errors) ** 0.5 / seeds
    if seeds > 1:
        se = max(se, statistics.stdev(flows) / seeds**0.5)
    return mean, se


def main():
    samples = int(sys.argv[1]) if len(sys.argv) > 1 else 200000
    rng = random.Random(1)
    print("| run noise / block error | seeds (cgdem + reference) | red by chance, one comparison | a night of 5 comparisons with one red |")
    print("|---|---|---|---|")
    for ratio in (1.0, 0.66):
        for seeds in ((1, 1), (3, 1), (3, 3)):
            red = 0
            for _ in range(samples):
                (a, sa), (b, sb) = side(seeds[0], ratio, rng), side(seeds[1], ratio, rng)
                red += abs(a - b) > 2.0 * (sa + sb)
            p = red / samples
            print(f"| {ratio} | {seeds[0]}+{seeds[1]} | {p:.3f} | {1 - (1 - p) ** 5:.2f} |")


if __name__ == "__main__":
    main()
