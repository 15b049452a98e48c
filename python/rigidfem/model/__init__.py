"""The model and its kinds: ``Model`` (what users edit) and ``System`` (compiled), joints, beams, materials and
sections, the laws of force elements and joint coordinates (``laws``), loops and actuators, prescribed motions
(``motion``), named parameters, moving bases and sea states (``sea``), the stages of the equations of motion and
the sample models. Imports the base layer and the compiled core only."""

from .model import Model, System

__all__ = ["Model", "System"]
