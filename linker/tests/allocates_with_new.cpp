// Breaks the rule on purpose: heap allocation with operator new.
int* make_counter() { return new int(42); }
void drop_counter(int* counter) { delete counter; }
