// The firmware-size bench's baseline: a program that does nothing (the C runtime's start-up only).
// SPDX-License-Identifier: BSL-1.0
int main() { return 0; }
