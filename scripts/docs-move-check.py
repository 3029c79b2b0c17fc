#!/usr/bin/env python3
"""Checks that moving the README's depth into docs/ lost nothing (issue 25): every number, every
inline code span (commands, tests, files) and every command line in a fence of the README at REV
(default 8fcfbad, before the move) must still appear in README.md + docs/*.md, as many times.
Prints what is missing; exits 1 if anything is.  Usage: python3 scripts/docs-move-check.py [REV]"""
import collections, glob, re, subprocess, sys

rev = sys.argv[1] if len(sys.argv) > 1 else '8fcfbad'
old = subprocess.run(['git', 'show', f'{rev}:README.md'], capture_output=True, text=True, check=True).stdout
new = open('README.md').read() + ''.join(open(f).read() for f in sorted(glob.glob('docs/*.md')))

def flat(t):  # figures and spans wrap across lines: compare them with whitespace collapsed
    return re.sub(r'\s+', ' ', t)

def prose(t):
    return re.sub(r'```.*?```', ' ', t, flags=re.S)

def numbers(t):
    return collections.Counter(re.findall(r'[-−~]?\d[\d,]*(?:\.\d+)?(?:e-?\d+)?', flat(t)))

def spans(t):
    return collections.Counter(s.strip() for s in re.findall(r'`([^`]+)`', flat(prose(t))))

def command_lines(t):
    pattern = r'(sunlit|npm|npx|cargo|node|cd|scripts/|fuzz/|LOUVRES|MODELS)\b'
    return collections.Counter(re.sub(r'\s+', ' ', l.strip()) for l in t.split('\n') if re.match(pattern, l.strip()))

missing = 0
for name, count in [('numbers', numbers), ('inline code spans', spans), ('command lines', command_lines)]:
    before, after = count(old), count(new)
    lost = before - after
    missing += sum(lost.values())
    print(f'{name}: {sum(before.values())} before, {sum(after.values())} after, {sum(lost.values())} missing')
    for text, n in sorted(lost.items()):
        print(f'  missing ({n}): {text}')
sys.exit(1 if missing else 0)
