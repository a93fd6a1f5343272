// Deliberately broken: the second statement misses its closing brace.
Point(1) = {0, 0, 0, 0.1};
Point(2) = {1, 0, 0, 0.1;
Line(1) = {1, 2};
