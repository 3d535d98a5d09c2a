// The program of each layer's link check (tests/CMakeLists.txt, "a call upward does not link"): it calls nothing; the
// layer's every object is linked in beside it, so an undefined symbol there is a call into a layer above.
int main() { return 0; }
