"""Photometric measurements (illuminance, luminance, intensity) of scenes.

Reserved: the photometry issue fills this module. Nothing is here yet.
"""

__all__: list = []
