#include <cstdio>
int main() { std::puts("lightcuts: under construction"); return 0; }
