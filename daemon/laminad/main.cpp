// laminad: placeholder until the job manager lands (issue 7 in progress).
int main() { return 0; }
