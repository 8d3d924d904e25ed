// Breaks the rule on purpose: heap allocation with malloc.
#include <cstdlib>
void* grab_buffer(std::size_t bytes) { return std::malloc(bytes); }
