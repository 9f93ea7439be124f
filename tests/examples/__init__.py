"""Tests of the client package and of the example scripts that use it."""
