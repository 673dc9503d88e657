"""``retrokit demo``: an agent plays the bundled test cartridge, then shows how it went.

It needs no ROM import: Dasher, retrokit's own Genesis game, ships in
``games/``. A scripted agent runs right and jumps now and then (sticky frame
skip 4, as in the Sonic benchmark); the command prints each episode's score
and saves a GIF of the best episode and a PNG of its last frame (under new
names if earlier ones are there: nothing is replaced).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from retrokit.errors import FileConflictError


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``demo`` command."""
    parser = subparsers.add_parser(
        "demo",
        help="play the bundled test cartridge with a scripted agent; save a GIF and a PNG",
        description="A scripted agent plays episodes of Dasher-Genesis (no ROM import needed), with a "
        "progress bar; then the episodes' scores are printed and a GIF of the best episode and a PNG of "
        "its last frame are saved.",
    )
    parser.add_argument("--game", default="Dasher-Genesis", help="the game (default: Dasher-Genesis)")
    parser.add_argument("--state", default=None, help="the start state (default: the game's)")
    parser.add_argument("--episodes", type=int, default=3, help="episodes to play (default: 3)")
    parser.add_argument("--max-steps", type=int, default=400, help="steps per episode at most (default: 400)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the agent and the sticky actions")
    parser.add_argument("--out", type=Path, default=Path("retrokit-demo"), help="folder for the GIF and PNG")
    parser.set_defaults(run=run)


class RunAndJump:
    """Hold RIGHT; now and then hold a jump button for a few steps."""

    def __init__(self, env, rng) -> None:  # a RetroEnv and a numpy Generator
        actions = env.unwrapped.actions
        self.run, self.jump = actions.press(["RIGHT"]), actions.press(["RIGHT", "B"])
        self.rng, self.jumping = rng, 0

    def act(self):  # an action of the env
        if self.jumping == 0 and self.rng.random() < 0.2:
            self.jumping = int(self.rng.integers(2, 6))
        if self.jumping:
            self.jumping -= 1
            return self.jump
        return self.run


def free_names(folder: Path, stem: str) -> tuple[Path, Path]:
    """A GIF and a PNG name in ``folder`` that are both unused: nothing there is replaced."""
    for n in range(10_000):
        base = stem if n == 0 else f"{stem}-{n}"
        gif, png = folder / f"{base}.gif", folder / f"{base}.png"
        if not gif.exists() and not png.exists():
            return gif, png
    raise FileConflictError(
        f"Expected a free file name for {stem} in {folder}; found all 10000 taken. Delete some, or pass --out."
    )


def run(args: argparse.Namespace) -> int:
    """Play, print the scores, save the pictures."""
    import io

    import numpy as np
    from PIL import Image
    from tqdm import tqdm

    import retrokit
    from retrokit.errors import InvalidArgumentError
    from retrokit.paths import atomic_write, ensure_folder

    if args.episodes < 1 or args.max_steps < 1:
        raise InvalidArgumentError(
            f"Expected --episodes and --max-steps of 1 or more, got {args.episodes} and {args.max_steps}."
        )
    ensure_folder(args.out, "for the GIF and PNG")  # before playing, so a bad --out costs nothing
    state = retrokit.State.DEFAULT if args.state is None else args.state
    env = retrokit.make(
        args.game, state, frameskip=4, sticky_prob=0.25, max_episode_steps=args.max_steps,
        action_type="all", render_mode="rgb_array",
    )
    rng = np.random.default_rng(args.seed)
    agent = RunAndJump(env, rng)
    results, best_frames, best_score = [], [], float("-inf")
    with tqdm(total=args.episodes * args.max_steps, unit="step", desc=f"{args.game}") as bar:
        for episode in range(args.episodes):
            env.reset(seed=args.seed + episode)
            frames, score, steps = [env.render()], 0.0, 0
            while True:
                _, reward, terminated, truncated, _info = env.step(agent.act())
                score += reward
                steps += 1
                bar.update(1)
                if steps % 2 == 0:
                    frames.append(env.render())
                if terminated or truncated:
                    break
            bar.update(args.max_steps - steps)  # an episode that ended early
            frames.append(env.render())
            results.append((episode + 1, score, steps, "done" if terminated else "time limit"))
            if score > best_score:
                best_score, best_frames = score, frames
    env.close()

    print(f"\n{'episode':>7}  {'score':>8}  {'steps':>5}  ended by")
    for episode, score, steps, ended in results:
        print(f"{episode:>7}  {score:>8.0f}  {steps:>5}  {ended}")
    scores = [r[1] for r in results]
    print(f"mean score {np.mean(scores):.1f}, best {max(scores):.0f}")

    gif, png = free_names(args.out, args.game)
    pictures = [Image.fromarray(f) for f in best_frames]
    gif_bytes, png_bytes = io.BytesIO(), io.BytesIO()
    pictures[0].save(gif_bytes, "GIF", save_all=True, append_images=pictures[1:], duration=2 * 4 * 1000 // 60, loop=0)
    pictures[-1].save(png_bytes, "PNG")
    try:
        atomic_write(gif, gif_bytes.getvalue())
        atomic_write(png, png_bytes.getvalue())
    except FileExistsError:  # another demo took the name meanwhile
        raise FileConflictError(f"Expected {gif} and {png} to be free; found one written meanwhile. Run again.") from None
    print(f"saved {gif} ({len(pictures)} frames) and {png}")
    return 0
