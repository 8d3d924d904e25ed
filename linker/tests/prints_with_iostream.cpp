// Breaks the rule on purpose: writes with iostreams.
#include <iostream>
void report(int value) { std::cout << value << '\n'; }
