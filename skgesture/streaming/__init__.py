"""Streaming recognition (temporary init)."""
from skgesture.streaming._recognizer import GestureEvent, StreamingRecognizer

__all__ = ["GestureEvent", "StreamingRecognizer"]
