"""Simulation: the scene, an actuator part in any model, systems of several actuators with contact, the model chosen for a stated accuracy, and rollouts."""
