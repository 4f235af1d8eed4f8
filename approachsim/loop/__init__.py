"""The closed loop: the stage that composes flight x sensors x navigation, and nothing else.

`closed_loop.NavInTheLoop` is the flight's navigation source: the profile's sensors and navigation system stepped
row by row inside the flown approach; `paths` chooses, once per run and by name with its reason, which code runs
it (the compiled row and aiding epoch, or the readable numpy path); `errors` splits a flown approach's error into
flight technical, navigation system and total system error. The physics stays in its stages (sensors/, nav/,
flight/) and the compiled arithmetic in core/loop/.
"""
