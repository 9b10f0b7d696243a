from masonrycli.cli import main

main()
