"""Figures. Each module imports matplotlib (Agg backend) only inside its functions."""
