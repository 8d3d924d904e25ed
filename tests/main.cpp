// Runs every CppUTest test linked into the executable, with CppUTest's memory-leak detector on.
#include <CppUTest/CommandLineTestRunner.h>

int main(int argc, char** argv) { return CommandLineTestRunner::RunAllTests(argc, argv); }
