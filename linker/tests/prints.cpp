// Breaks the rule on purpose: writes with stdio.
#include <cstdio>
void report(int value) { std::printf("value %d\n", value); }
