"""The schema of a deploy profile: what the YAML files of ``deploy/`` may say, validated.

It sits below ``components`` and ``deploy``: every process reads its profile, the launcher
and the tools too, and none of them is imported by it.
"""
