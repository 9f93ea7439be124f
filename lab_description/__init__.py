"""The lab as data: the world file (stations, nests, markers, POIs, plates), read and checked."""
