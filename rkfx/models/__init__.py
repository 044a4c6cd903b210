"""Models for the steppers: elastostatics, equal-order u-p Biot, the damaging bar, damage dynamics."""
