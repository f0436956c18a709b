%
G 90 G 94 G 17 G 21
T 1 M 6
S 5 0 0 0 M 3
G 0 X 1 0 Y 5 Z 5
G 1 Z - 1 F 2 0 0
X 3 0 . 5 F 6 0 0
G 2 X 4 0 . 5 Y 1 5 I 0 J 1 0
G 0 Z 5
M 5
M 3 0
%
