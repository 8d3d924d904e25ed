// Breaks the rule on purpose: throws an exception (built with exceptions on, as a careless file would be).
#include <stdexcept>
int checked_divide(int a, int b) {
  if (b == 0) {
    throw std::invalid_argument("divide by zero");
  }
  return a / b;
}
