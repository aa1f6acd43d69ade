// placeholder replaced by the mrf command line
int main() { return 0; }
