"""An agent a user writes (the ``puzzlebox.learning.Agent`` protocol, nothing of ours): each component in turn.
The same as the README's Python API example; the CLI test writes this file beside ``trial.py``'s working folder."""


class TryInTurn:
    """A user's agent: each component in turn."""

    name = "try-in-turn"

    def begin_episode(self, observation, rng):
        self.turn = 0

    def choose(self, observation):
        self.turn += 1
        return (self.turn - 1) % len(observation.components)

    def record(self, index, result, observation):
        pass

    def end_episode(self, solved):
        pass
