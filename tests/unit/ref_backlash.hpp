#pragma once
// Reference backlash with a gap per direction (Tao & Kokotović's characteristic), written
// independently of lash's Deadband and BacklashInverse: the tests' oracle for the inverse
// (test_inverses.cpp) and for the carts' adaptive compensator (test_adaptive_compensator.cpp).
namespace lash::test {
struct RefBacklash {
  double cr, cl, y;  // gap pushing up, gap pushing down [position unit], output
  double step(double w) {
    if (w > y + cr) y = w - cr;
    else if (w < y - cl) y = w + cl;
    return y;
  }
};
}  // namespace lash::test
