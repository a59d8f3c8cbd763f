#include <cstdio>
int main() { std::puts("mcdenoise"); return 0; }
